#pragma once
// How far one flow field is from a reference, pixel by pixel: what the tests' fp16 bound and
// neuflow-gpu-check's checks are stated in. No test framework, so the GPU check can use it.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "neuflow/flow/flow_field.hpp"

namespace neuflow::test {

struct FlowDifference {
  double max = 0, mean = 0;           // of each component's absolute difference, px
  double epe = 0, worst = 0;          // mean and largest end-point error, px
  double magnitude = 0, largest = 0;  // mean and largest |flow| of the reference, px
};

// Over the pixels both fields have.
inline FlowDifference flow_difference(const flow::FlowField& reference, const flow::FlowField& other) {
  FlowDifference d;
  const std::size_t n = std::min(reference.pixel_count(), other.pixel_count());
  for (std::size_t p = 0; p < n; ++p) {
    const double du = other.uv[2 * p] - reference.uv[2 * p], dv = other.uv[2 * p + 1] - reference.uv[2 * p + 1];
    d.max = std::max({d.max, std::fabs(du), std::fabs(dv)});
    d.mean += (std::fabs(du) + std::fabs(dv)) / 2;
    const double e = std::hypot(du, dv);
    const double m = std::hypot(static_cast<double>(reference.uv[2 * p]), static_cast<double>(reference.uv[2 * p + 1]));
    d.epe += e;
    d.worst = std::max(d.worst, e);
    d.magnitude += m;
    d.largest = std::max(d.largest, m);
  }
  const double count = static_cast<double>(std::max<std::size_t>(n, 1));
  d.mean /= count;
  d.epe /= count;
  d.magnitude /= count;
  return d;
}

// How many of the two fields' values differ bit for bit (their sizes' difference counted too):
// 0 where two ways of computing promise the same sums in the same order.
inline std::size_t differing_values(const flow::FlowField& a, const flow::FlowField& b) {
  const std::size_t n = std::min(a.uv.size(), b.uv.size());
  std::size_t differing = std::max(a.uv.size(), b.uv.size()) - n;
  for (std::size_t i = 0; i < n; ++i) {
    differing += std::bit_cast<std::uint32_t>(a.uv[i]) != std::bit_cast<std::uint32_t>(b.uv[i]) ? 1 : 0;
  }
  return differing;
}

}  // namespace neuflow::test
