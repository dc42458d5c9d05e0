// A whole checkpoint file through load_checkpoint: the file checks, the zip container
// (libzip), the restricted unpickler and tensor materialization; never inference.
// CheckpointError is the documented failure. Mutations of a zip's entries mostly fail its
// CRC check, so the pickle itself is fuzzed behind a fixed container by checkpoint_pickle.
#include <cstddef>
#include <cstdint>

#include "checkpoint_support.hpp"
#include "fuzz_support.hpp"
#include "neuflow/model/checkpoint.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static neuflow::fuzz::InputFile file("fuzz-input.pth");
  try {
    const auto checkpoint = neuflow::model::load_checkpoint(file.write(data, size));
    neuflow::fuzz::check_checkpoint("checkpoint", checkpoint);
  } catch (const neuflow::model::CheckpointError&) {
  } catch (...) {
    neuflow::fuzz::unexpected_exception("checkpoint");
  }
  return 0;
}
