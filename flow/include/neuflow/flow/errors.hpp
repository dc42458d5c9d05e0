#pragma once
// The one exception type of the flow-file readers and writers. Its message always names the
// file, so a tool can print what() as it is; kind() lets callers map failures to exit codes
// without parsing text.
#include <filesystem>
#include <stdexcept>
#include <string>

namespace neuflow::flow {

class FlowFileError : public std::runtime_error {
 public:
  enum class Kind {
    not_found,           // missing, unreadable, or not a regular file
    malformed,           // contents do not follow the format (magic, sizes, dtype, bit depth…)
    unsupported_format,  // the extension names no flow format we know
    write_failed,        // the output (or its temporary sibling) could not be written
  };

  FlowFileError(Kind kind, std::filesystem::path path, const std::string& problem);

  Kind kind() const noexcept { return kind_; }
  const std::filesystem::path& path() const noexcept { return path_; }
  // The message without the leading file name.
  const std::string& problem() const noexcept { return problem_; }

 private:
  Kind kind_;
  std::filesystem::path path_;
  std::string problem_;
};

}  // namespace neuflow::flow
