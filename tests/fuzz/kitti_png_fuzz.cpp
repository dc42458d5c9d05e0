// KITTI 16-bit flow PNG reader (read_kitti_png): our PNG header parsing and checks, then
// OpenCV/libpng's decoder. libpng checks chunk CRCs, so most mutations of the image data end
// there as a FlowFileError; the header checks before decoding get the most attention.
#include <cstddef>
#include <cstdint>

#include "flow_checks.hpp"
#include "fuzz_support.hpp"
#include "neuflow/flow/errors.hpp"
#include "neuflow/flow/kitti_png_format.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static neuflow::fuzz::InputFile file("fuzz-input.png");
  try {
    const auto field = neuflow::flow::read_kitti_png(file.write(data, size));
    neuflow::fuzz::check_flow_field("kitti_png", field, {.always_masked = true, .max_magnitude = 512.f});
  } catch (const neuflow::flow::FlowFileError&) {
  } catch (...) {
    neuflow::fuzz::unexpected_exception("kitti_png");
  }
  return 0;
}
