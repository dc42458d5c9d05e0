// Middlebury .flo reader (read_flo). FlowFileError is the documented failure; anything else
// escaping it, a sanitizer report, or a field that breaks the format's promises is a finding.
#include <cstddef>
#include <cstdint>

#include "flow_checks.hpp"
#include "fuzz_support.hpp"
#include "neuflow/flow/errors.hpp"
#include "neuflow/flow/flo_format.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static neuflow::fuzz::InputFile file("fuzz-input.flo");
  try {
    const auto field = neuflow::flow::read_flo(file.write(data, size));
    neuflow::fuzz::check_flow_field(
        "flo", field, {.never_all_valid_mask = true, .max_magnitude = neuflow::flow::kFloUnknownThreshold});
  } catch (const neuflow::flow::FlowFileError&) {
  } catch (...) {
    neuflow::fuzz::unexpected_exception("flo");
  }
  return 0;
}
