#include "written_files.hpp"

namespace neuflow::gst {

bool WrittenFiles::superseded(const Entry &e) const {
  const auto it = newest_.find(e.path);
  return it == newest_.end() || it->second != e.serial;
}

void WrittenFiles::add(const std::string &path, std::uint64_t bytes) {
  // entries_ only ever loses its front, so an entry's position is its serial minus the
  // front's: the superseded entry is found without a scan.
  if (const auto it = newest_.find(path); it != newest_.end()) {
    const Entry &old = entries_[static_cast<std::size_t>(it->second - entries_.front().serial)];
    bytes_ -= old.bytes;
  }
  const std::uint64_t serial = next_serial_++;
  entries_.push_back({path, bytes, serial});
  newest_[path] = serial;
  bytes_ += bytes;
}

std::vector<std::string> WrittenFiles::take_excess(std::uint64_t max_files, std::uint64_t max_bytes) {
  std::vector<std::string> excess;
  auto over = [&] { return (max_files > 0 && newest_.size() > max_files) || (max_bytes > 0 && bytes_ > max_bytes); };
  while (!entries_.empty() && (superseded(entries_.front()) || (over() && newest_.size() > 1))) {
    Entry e = std::move(entries_.front());
    entries_.pop_front();
    if (superseded(e)) continue;  // its newer entry is further back
    newest_.erase(e.path);
    bytes_ -= e.bytes;
    excess.push_back(std::move(e.path));
  }
  return excess;
}

}  // namespace neuflow::gst
