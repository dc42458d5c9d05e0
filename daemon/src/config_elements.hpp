#pragma once
// The GStreamer elements each part of a stream is built from, so that a missing plugin is
// reported when the config is checked instead of when the stream starts (internal to the
// config loader; stream_graph.cpp is what actually builds them, keep the two in step).
#include <string>
#include <vector>

#include "config.hpp"

namespace neuflow::daemon {

std::vector<std::string> elements_for(const SourceSettings& source);
std::vector<std::string> elements_for_flow();
std::vector<std::string> elements_for(const SinkSettings& sink);

// The elements of this project's plugin (libgstneuflow.so).
bool is_neuflow_element(const std::string& factory);

}  // namespace neuflow::daemon
