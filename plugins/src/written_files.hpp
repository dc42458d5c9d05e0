#pragma once
// The flow files a neuflowsink run has written, oldest first, with their sizes: which ones
// have to go so that at most max-files files and max-bytes bytes remain. Bookkeeping only;
// the element deletes the files. No GStreamer in here.
#include <cstdint>
#include <deque>
#include <string>
#include <unordered_map>
#include <vector>

namespace neuflow::gst {

class WrittenFiles {
 public:
  // Records a file just written. Writing a path again (the index property was set back)
  // supersedes its earlier entry: it counts once, at its newest position.
  void add(const std::string &path, std::uint64_t bytes);

  // Forgets the oldest files until at most `max_files` remain and they hold at most
  // `max_bytes` (0: no limit), and returns them, oldest first, for deletion. The newest file
  // is always kept, even when it alone exceeds max_bytes: a sink that deleted what it just
  // wrote would be useless.
  std::vector<std::string> take_excess(std::uint64_t max_files, std::uint64_t max_bytes);

  std::size_t count() const { return newest_.size(); }
  std::uint64_t bytes() const { return bytes_; }

 private:
  struct Entry {
    std::string path;
    std::uint64_t bytes;
    std::uint64_t serial;
  };
  bool superseded(const Entry &e) const;

  std::deque<Entry> entries_;                              // oldest first, superseded ones included
  std::unordered_map<std::string, std::uint64_t> newest_;  // path → serial of its live entry
  std::uint64_t next_serial_ = 0;
  std::uint64_t bytes_ = 0;  // of live entries
};

}  // namespace neuflow::gst
