#pragma once
// Shared by the fuzz harnesses: the input as a file for the readers that take a path, the
// report for an exception the code under test does not document, and checks of what a
// successful read returned.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

namespace neuflow::fuzz {

// The current input as a file: an anonymous memory file (memfd) of this process, reached as
// /proc/self/fd/N. Nothing is left behind when the process dies, and fuzzers running side by
// side never share it.
class InputFile {
 public:
  explicit InputFile(const char* name);
  ~InputFile();
  InputFile(const InputFile&) = delete;
  InputFile& operator=(const InputFile&) = delete;

  // Replaces the contents with the input; returns path().
  const std::filesystem::path& write(const std::uint8_t* data, std::size_t size);
  const std::filesystem::path& path() const { return path_; }

 private:
  int fd_ = -1;
  std::filesystem::path path_;
};

// For an exception the code under test does not document: prints its type and message and
// aborts, so that libFuzzer reports the input as a crash. Call it from a catch block.
[[noreturn]] void unexpected_exception(const char* harness) noexcept;

// A broken promise about a successful result: prints it and aborts (a finding, like a crash).
[[noreturn]] void invariant_failed(const char* harness, const std::string& what) noexcept;

}  // namespace neuflow::fuzz
