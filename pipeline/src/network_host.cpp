#include "network_host.hpp"

#include <gst/gst.h>
#include <netdb.h>
#include <sys/socket.h>

namespace neuflow::pipeline::detail {

std::optional<std::string> unresolvable_host(const std::string& uri) {
  GstUri* parsed = gst_uri_from_string(uri.c_str());
  if (!parsed) return std::nullopt;
  const gchar* h = gst_uri_get_host(parsed);
  const std::string host = h ? h : "";
  gst_uri_unref(parsed);
  if (host.empty()) return std::nullopt;
  addrinfo hints{};
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  const int status = getaddrinfo(host.c_str(), nullptr, &hints, &found);
  if (found) freeaddrinfo(found);
  if (status == 0) return std::nullopt;
  return "cannot resolve the host '" + host + "' (" + gai_strerror(status) + ")";
}

}  // namespace neuflow::pipeline::detail
