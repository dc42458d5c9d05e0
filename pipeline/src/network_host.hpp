#pragma once
// Why a network source failed, where GStreamer does not say: its host does not resolve.
// souphttpsrc, for one, reports only "Internal data stream error" for an unknown host.
#include <optional>
#include <string>

namespace neuflow::pipeline::detail {

// "cannot resolve the host 'cam.example' (Name or service not known)" when `uri` names a host
// that the resolver does not know; nothing for a local URI, an address, or a host that resolves.
std::optional<std::string> unresolvable_host(const std::string& uri);

}  // namespace neuflow::pipeline::detail
