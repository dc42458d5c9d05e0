#pragma once
// Checks what a config refers to on this machine (internal to the config loader): that the
// files it reads exist and can be read, that camera device nodes are there and usable, that
// output folders exist or can be created, and that the GStreamer elements and URI handlers
// its streams need are installed. Nothing is loaded, opened for long or created.
#include <functional>
#include <string>

#include "config_issues.hpp"
#include "config_read.hpp"

namespace neuflow::daemon {

// What GStreamer has installed; a seam so that tests can take plugins away.
struct GstInventory {
  std::function<bool(const std::string& factory)> has_element;
  std::function<bool(const std::string& scheme)> reads_uri_scheme;
};

// The real registry. gst_init() must have been called.
GstInventory installed_gstreamer();

// What the machine lacks now goes to `issues` (warnings: the daemon waits for it); a model
// file that exists but is no NeuFlow-V2 checkpoint goes to `errors`, since waiting will not
// change it.
void check_machine(const MachineNeeds& needs, const GstInventory& gstreamer, Issues& issues, Issues& errors);
inline void check_machine(const MachineNeeds& needs, const GstInventory& gstreamer, Issues& issues) {
  check_machine(needs, gstreamer, issues, issues);
}

}  // namespace neuflow::daemon
