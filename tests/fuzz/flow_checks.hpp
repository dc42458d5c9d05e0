#pragma once
// What every flow reader promises about a field it returns (flow_field.hpp and the format
// headers): a size within limits.hpp, consistent buffers, finite values, and the zero
// placeholder for invalid pixels.
#include <cmath>
#include <cstddef>
#include <limits>
#include <string>

#include "fuzz_support.hpp"
#include "neuflow/flow/flow_field.hpp"
#include "neuflow/flow/limits.hpp"

namespace neuflow::fuzz {

struct FlowPromises {
  bool always_masked = false;         // KITTI: the mask is always there
  bool never_all_valid_mask = false;  // .flo/.npy: the mask is left empty when every pixel is valid
  float max_magnitude = std::numeric_limits<float>::infinity();  // of a valid u or v
};

inline void check_flow_field(const char* harness, const flow::FlowField& f, const FlowPromises& promises) {
  const auto fail = [&](const std::string& what) {
    invariant_failed(harness, what + " (field " + std::to_string(f.width) + "x" + std::to_string(f.height) + ")");
  };
  if (!flow::flow_size_acceptable(f.width, f.height)) fail("size outside limits.hpp");
  const std::size_t n = f.pixel_count();
  if (f.uv.size() != 2 * n) fail("uv holds " + std::to_string(f.uv.size()) + " values");
  if (!f.valid.empty() && f.valid.size() != n) fail("mask of " + std::to_string(f.valid.size()) + " entries");
  if (promises.always_masked && f.valid.empty()) fail("no mask");
  bool any_invalid = false;
  for (std::size_t i = 0; i < n; ++i) {
    const float u = f.uv[2 * i];
    const float v = f.uv[2 * i + 1];
    if (!std::isfinite(u) || !std::isfinite(v)) fail("non-finite value at pixel " + std::to_string(i));
    const bool valid = f.valid.empty() || f.valid[i] != 0;
    if (!f.valid.empty() && f.valid[i] > 1) fail("mask value " + std::to_string(f.valid[i]));
    if (!valid) {
      any_invalid = true;
      if (u != 0.f || v != 0.f) fail("invalid pixel " + std::to_string(i) + " without the zero placeholder");
    } else if (std::fabs(u) > promises.max_magnitude || std::fabs(v) > promises.max_magnitude) {
      fail("valid pixel " + std::to_string(i) + " beyond " + std::to_string(promises.max_magnitude));
    }
  }
  if (promises.never_all_valid_mask && !f.valid.empty() && !any_invalid) fail("a mask with every pixel valid");
}

}  // namespace neuflow::fuzz
