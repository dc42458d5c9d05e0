#pragma once
// What earlier runs of a neuflowsink left in its folder: the flow files its location pattern
// names (so max-files / max-bytes count them too, after a restart or a reload), and the hidden
// temporaries of writes that a crash or kill -9 interrupted. No GStreamer in here (GLib formats
// the names).
#include <cstdint>
#include <string>
#include <vector>

namespace neuflow::gst {

// The file name `pattern` (one integer conversion, checked by the sink) gives file `index`: how
// the sink names what it writes, and what retention matches names against.
std::string format_index_name(const std::string& pattern, int index);

struct EarlierFile {
  std::string path;
  std::int64_t index = 0;  // the number the pattern's conversion put in its name
  std::uint64_t bytes = 0;
};

// The regular files in `pattern`'s folder whose names the pattern produces for some index
// ("flow_%05d.flo" matches flow_00042.flo; "%%" stands for a literal '%'), in index order:
// oldest first, as the sink numbers them. `pattern` must hold exactly one integer conversion.
std::vector<EarlierFile> files_matching(const std::string& pattern);

// Removes the temporaries that atomic writes leave when interrupted — ".NAME.tmp-XXXXXXXX"
// beside NAME — for every NAME the pattern produces and for `index_path` (when not empty).
// Returns the paths removed. Call it only while no writer of these files runs.
std::vector<std::string> remove_stale_temporaries(const std::string& pattern, const std::string& index_path);

}  // namespace neuflow::gst
