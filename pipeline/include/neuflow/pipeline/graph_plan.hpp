#pragma once
// A graph description as GStreamer element chains — the one place that says which elements a
// source, the flow stage and each kind of sink are made of and how they are set. From it come
// the elements a machine must have installed (required_elements), the graph itself
// (stream_graph.hpp), the RTSP server's media (rtsp_launch_line) and each sink's kind for
// logs and metric labels.
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "neuflow/pipeline/element_chain.hpp"
#include "neuflow/pipeline/graph_description.hpp"

namespace neuflow::pipeline {

struct SourcePlan {
  ElementChain chain;    // linked in order; its last element feeds the flow stage
  bool dynamic = false;  // the first element (uridecodebin) links its video pad once typed
};

struct SinkPlan {
  std::string_view kind;                       // sink_kind()
  ElementChain chain;                          // starts with the branch's queue
  std::vector<std::filesystem::path> folders;  // to exist before the chain is built
};

// What a plan may need to know of the machine; the defaults know nothing.
// Where a display sink can show its window, from the environment alone: a Wayland compositor
// (WAYLAND_DISPLAY), an X server (DISPLAY), or none. Never by probing: autovideosink tries
// kmssink and dfbvideosink in-process, which crashed the whole daemon on a machine without a
// display.
enum class DisplayServer { none, wayland, x11 };
DisplayServer display_server_from_environment();
// Why a display sink cannot be built where there is no display.
std::string no_display_reason();

struct PlanContext {
  // The first file index not used yet by files matching a printf-style pattern, so a restarted
  // stream never overwrites what an earlier run wrote.
  std::function<int(const std::string& pattern)> first_free_index = [](const std::string&) { return 0; };
  // A display sink's window: waylandsink, ximagesink, or (none) a sink that cannot be built.
  std::function<DisplayServer()> display_server = display_server_from_environment;
};

SourcePlan plan_source(const SourceDescription& source);
// videoconvert → neuflow; session.threads is given to the element as is.
ElementChain plan_flow(const FlowStage& flow);
SinkPlan plan_sink(const std::string& graph, const NamedSink& sink, const PlanContext& context = {});

// "files", "shm", "video-file", "rtsp", "udp" or "display".
std::string_view sink_kind(const SinkDescription& sink);

// The factories each part needs; for an RTSP sink also those of the server's media.
std::vector<std::string> required_elements(const SourceDescription& source);
std::vector<std::string> required_elements(const FlowStage& flow);
std::vector<std::string> required_elements(const SinkDescription& sink);

// The intervideo channel that carries a graph's visualization to an RTSP mount.
std::string rtsp_channel_name(const std::string& graph, const std::string& mount);
// The RTSP server's media for a mount: the channel, encoded to H.264 and packetized, in the
// launch syntax GstRTSPMediaFactory takes.
std::string rtsp_launch_line(const std::string& channel, int bitrate_kbps);

// The first index not used yet by files matching printf-style `pattern` ("…%05d…") in its
// folder (PlanContext::first_free_index on this machine).
int next_free_index(const std::string& pattern);

}  // namespace neuflow::pipeline
