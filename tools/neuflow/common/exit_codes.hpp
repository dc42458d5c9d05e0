#pragma once
// Exit codes (sysexits.h) for the classes of failure a script may want to tell apart, and the
// error a subcommand (or a library behind it) throws to end with one.
#include <stdexcept>
#include <string>

namespace neuflow::flow {
class FlowFileError;
}
namespace neuflow::model {
class CheckpointError;
}

namespace neuflow::cli {

inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;
inline constexpr int kExitUsage = 64;        // EX_USAGE: the command line is wrong (CLI11's own codes are not used)
inline constexpr int kExitDataError = 65;    // EX_DATAERR: an input file is malformed
inline constexpr int kExitNoInput = 66;      // EX_NOINPUT: an input file is missing or unreadable
inline constexpr int kExitUnavailable = 69;  // EX_UNAVAILABLE: the GPU backend (Vulkan, its device) failed
inline constexpr int kExitCantCreate = 73;   // EX_CANTCREAT: an output could not be written
inline constexpr int kExitConfig = 78;       // EX_CONFIG: the environment's settings are wrong (NEUFLOW_CONV)

// Thrown from a subcommand's callback: main prints "neuflow <sub>: <message>" and exits
// with exit_code.
struct CommandError : std::runtime_error {
  CommandError(int code, const std::string& message) : std::runtime_error(message), exit_code(code) {}
  int exit_code;
};

// The exit code for a failure to read or write a flow file, or to load a checkpoint.
int exit_code_for(const flow::FlowFileError& e);
int exit_code_for(const model::CheckpointError& e);

}  // namespace neuflow::cli
