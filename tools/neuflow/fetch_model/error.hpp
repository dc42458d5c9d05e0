#pragma once
// The one exception of `neuflow fetch-model`'s download machinery. Its kind decides the exit
// code; what() is the whole message for the user (it names the URL or file and what happened).
#include <stdexcept>
#include <string>

namespace neuflow::cli {

class FetchError : public std::runtime_error {
 public:
  enum class Kind {
    kUnavailable,  // the server could not be reached or did not deliver the file
    kIntegrity,    // the bytes arrived but are not the pinned file (or not a checkpoint)
    kLocalIo,      // the output directory or file could not be written
    kInterrupted,  // SIGINT/SIGTERM during the download
  };
  FetchError(Kind kind, const std::string& message) : std::runtime_error(message), kind_(kind) {}
  Kind kind() const noexcept { return kind_; }

 private:
  Kind kind_;
};

}  // namespace neuflow::cli
