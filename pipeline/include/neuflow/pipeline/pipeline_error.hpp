#pragma once
// The one exception type of the GStreamer helpers. Its message always starts with the file
// (or URI) it is about, so a tool can print what() as it is; kind() lets callers map failures
// to exit codes without parsing text.
#include <stdexcept>
#include <string>

namespace neuflow::pipeline {

class PipelineError : public std::runtime_error {
 public:
  enum class Kind {
    not_found,         // the input file does not exist or cannot be read
    undecodable,       // GStreamer cannot decode it, or it has no video stream
    missing_element,   // a GStreamer element this needs is not installed
    write_failed,      // the output (or its temporary sibling) could not be written
    invalid_argument,  // the caller asked for something unusable (size, extension…)
    failed,            // anything else GStreamer reported
  };

  PipelineError(Kind kind, std::string subject, const std::string& problem);

  Kind kind() const noexcept { return kind_; }
  // The file or URI the error is about.
  const std::string& subject() const noexcept { return subject_; }
  // The message without the leading subject.
  const std::string& problem() const noexcept { return problem_; }

 private:
  Kind kind_;
  std::string subject_;
  std::string problem_;
};

}  // namespace neuflow::pipeline
