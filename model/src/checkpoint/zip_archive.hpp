#pragma once
// Read-only access to the entries of a zip archive through libzip. Internal to neuflow_model.
// Errors are CheckpointError without the file name (load_checkpoint adds it).
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

struct zip;

namespace neuflow::model::detail {

class ZipArchive {
 public:
  // Opens `path` read-only. Throws CheckpointError: kIo when the file cannot be opened,
  // kFormat when it is not a (complete, consistent) zip archive.
  explicit ZipArchive(const std::filesystem::path& path);
  ~ZipArchive();
  ZipArchive(const ZipArchive&) = delete;
  ZipArchive& operator=(const ZipArchive&) = delete;

  // Entry names in central-directory order.
  const std::vector<std::string>& names() const { return names_; }
  bool contains(const std::string& name) const { return find(name).has_value(); }
  // Uncompressed size of an entry (as the central directory states it), or nullopt.
  std::optional<uint64_t> size_of(const std::string& name) const;
  // The whole uncompressed entry. Throws CheckpointError (kFormat) when it is missing, larger
  // than max_bytes, or its data is truncated/corrupt.
  std::vector<unsigned char> read(const std::string& name, uint64_t max_bytes) const;

 private:
  std::optional<uint64_t> find(const std::string& name) const;

  ::zip* archive_ = nullptr;
  uint64_t file_size_ = 0;
  std::vector<std::string> names_;
};

}  // namespace neuflow::model::detail
