// The pickle of a checkpoint (data.pkl), inside a valid container: the input becomes
// archive/data.pkl of a zip (correct CRCs) beside four 256-byte storages archive/data/0..3,
// and the whole file goes through load_checkpoint. So the unpickler, the state-dict layouts
// and tensor materialization (offsets, strides, dtypes against real storages) see every
// mutation. CheckpointError is the documented failure.
#include <cstddef>
#include <cstdint>
#include <string>

#include "checkpoint_support.hpp"
#include "fuzz_support.hpp"
#include "neuflow/model/checkpoint.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static neuflow::fuzz::InputFile file("fuzz-input-pickle.pth");
  const std::string zip =
      neuflow::fuzz::checkpoint_around_pickle(std::string(reinterpret_cast<const char*>(data), size));
  try {
    const auto checkpoint =
        neuflow::model::load_checkpoint(file.write(reinterpret_cast<const std::uint8_t*>(zip.data()), zip.size()));
    neuflow::fuzz::check_checkpoint("checkpoint_pickle", checkpoint);
  } catch (const neuflow::model::CheckpointError&) {
  } catch (...) {
    neuflow::fuzz::unexpected_exception("checkpoint_pickle");
  }
  return 0;
}
