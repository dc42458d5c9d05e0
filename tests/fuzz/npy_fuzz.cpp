// NumPy .npy readers: read_npy (an H×W×2 flow field) and read_npy_array (any float32 array,
// as the reference tools dump tensors), both on every input. FlowFileError is the documented
// failure of both.
#include <cstddef>
#include <cstdint>
#include <string>

#include "flow_checks.hpp"
#include "fuzz_support.hpp"
#include "neuflow/flow/errors.hpp"
#include "neuflow/flow/npy_format.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static neuflow::fuzz::InputFile file("fuzz-input.npy");
  const auto& path = file.write(data, size);
  try {
    const auto field = neuflow::flow::read_npy(path);
    neuflow::fuzz::check_flow_field("npy", field, {.never_all_valid_mask = true});
  } catch (const neuflow::flow::FlowFileError&) {
  } catch (...) {
    neuflow::fuzz::unexpected_exception("npy (read_npy)");
  }
  try {
    const auto array = neuflow::flow::read_npy_array(path);
    std::uint64_t count = 1;
    for (const auto d : array.shape) {
      if (d < 0) neuflow::fuzz::invariant_failed("npy (read_npy_array)", "negative dimension");
      count *= static_cast<std::uint64_t>(d);
    }
    // The data size must match the file exactly (npy_format.hpp).
    if (count != array.data.size() || 4 * count > size) {
      neuflow::fuzz::invariant_failed("npy (read_npy_array)", std::to_string(array.data.size()) +
                                                                  " values for a shape of " + std::to_string(count) +
                                                                  " elements in a file of " + std::to_string(size) +
                                                                  " bytes");
    }
  } catch (const neuflow::flow::FlowFileError&) {
  } catch (...) {
    neuflow::fuzz::unexpected_exception("npy (read_npy_array)");
  }
  return 0;
}
