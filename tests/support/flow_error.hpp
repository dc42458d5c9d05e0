#pragma once
// How far a flow computed with fp16 operands is from an exact one, as the fp16 bound
// (docs/benchmarks.md) states it: relative to the flow's size, since the random-weight fixture
// model gives flows of hundreds of pixels.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>

#include "neuflow/flow/flow_field.hpp"

namespace neuflow::test {

struct Fp16Error {
  double epe = 0, worst = 0;          // mean and largest end-point error, px
  double magnitude = 0, largest = 0;  // mean and largest |flow| of the exact flow, px
};

// Printed with `what` ("fp16 vs fp32") and the size.
inline Fp16Error fp16_error(const flow::FlowField& exact, const flow::FlowField& half, int w, int h,
                            const char* what = "fp16 vs fp32") {
  Fp16Error r;
  const std::size_t n = exact.pixel_count();
  EXPECT_EQ(half.pixel_count(), n);
  for (std::size_t p = 0; p < n && p < half.pixel_count(); ++p) {
    const double du = half.uv[2 * p] - exact.uv[2 * p], dv = half.uv[2 * p + 1] - exact.uv[2 * p + 1];
    const double e = std::sqrt(du * du + dv * dv);
    const double m = std::hypot(static_cast<double>(exact.uv[2 * p]), static_cast<double>(exact.uv[2 * p + 1]));
    r.epe += e;
    r.magnitude += m;
    r.worst = std::max(r.worst, e);
    r.largest = std::max(r.largest, m);
  }
  r.epe /= static_cast<double>(std::max<std::size_t>(n, 1));
  r.magnitude /= static_cast<double>(std::max<std::size_t>(n, 1));
  std::printf(
      "%s at %dx%d: mean EPE %.4f px (%.3f %% of the mean |flow| %.2f px), max %.4f px "
      "(%.3f %% of the largest |flow| %.2f px)\n",
      what, w, h, r.epe, 100 * r.epe / r.magnitude, r.magnitude, r.worst, 100 * r.worst / r.largest, r.largest);
  return r;
}

// The fp16 bound: mean EPE under 0.5 % of the mean |flow|, no pixel off by more than 1 % of
// the largest vector.
inline void expect_within_fp16_bound(const Fp16Error& e, const char* where) {
  EXPECT_LT(e.epe, 0.005 * e.magnitude) << where;
  EXPECT_LT(e.worst, 0.01 * e.largest) << where;
}

}  // namespace neuflow::test
