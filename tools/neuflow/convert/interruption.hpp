#pragma once
// Ctrl-C (SIGINT) or SIGTERM during `neuflow convert`: the pair being computed is finished,
// then the conversion stops there, writes the index of what is complete, leaves no partial
// file behind and says how to go on. A second signal ends the process at once (the default
// action), for a conversion stuck somewhere no pair ends.
#include <filesystem>

namespace neuflow::cli {

class InterruptionHandler {
 public:
  // Installs the handlers for SIGINT and SIGTERM; the destructor restores the earlier ones.
  InterruptionHandler();
  ~InterruptionHandler();
  InterruptionHandler(const InterruptionHandler&) = delete;
  InterruptionHandler& operator=(const InterruptionHandler&) = delete;
};

// The signal that asked the conversion to stop, or 0.
int interruption_signal();

// Removes what writers that no longer run left in `folder`: their temporary files
// (".viz.mp4.partial-<pid>-<n>", "settings.toml.partial-<pid>") whose process is gone. What a
// running writer (another shard) is writing stays.
void remove_stale_partials(const std::filesystem::path& folder);

}  // namespace neuflow::cli
