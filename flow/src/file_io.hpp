#pragma once
// File access shared by the format readers and writers (internal to neuflow_flow).
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace neuflow::flow::detail {

// An input file opened for sequential binary reads. Errors throw FlowFileError naming the
// file: not_found when it cannot be opened, malformed when a read comes up short.
class BinaryInput {
 public:
  explicit BinaryInput(const std::filesystem::path& path);

  std::uint64_t size() const { return size_; }
  const std::filesystem::path& path() const { return path_; }
  // Reads exactly out.size() bytes; `what` names the part for the truncation message.
  void read(std::span<std::byte> out, const char* what);

 private:
  struct Closer {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  std::filesystem::path path_;
  std::unique_ptr<std::FILE, Closer> file_;
  std::uint64_t size_ = 0;
  std::uint64_t position_ = 0;
};

// The whole file, refusing files larger than max_bytes before reading them.
std::vector<std::byte> read_whole_file(const std::filesystem::path& path, std::uint64_t max_bytes);

// Writes bytes to a temporary file beside path, flushes it to disk and renames it over path,
// so readers (and a crash) see the old file or the complete new one, never a partial one.
// On failure the temporary file is removed and FlowFileError (write_failed) is thrown.
// A symlink at path is replaced by the new file, not followed.
void write_file_atomically(const std::filesystem::path& path, std::span<const std::byte> bytes);

}  // namespace neuflow::flow::detail
