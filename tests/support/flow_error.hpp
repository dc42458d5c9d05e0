#pragma once
// How far a flow computed with fp16 operands is from an exact one, as the fp16 bound
// (docs/benchmarks.md) states it: relative to the flow's size, since the random-weight fixture
// model gives flows of hundreds of pixels.
#include <gtest/gtest.h>

#include <cstdio>

#include "neuflow/flow/flow_field.hpp"
#include "support/flow_difference.hpp"

namespace neuflow::test {

using Fp16Error = FlowDifference;

// Printed with `what` ("fp16 vs fp32") and the size.
inline Fp16Error fp16_error(const flow::FlowField& exact, const flow::FlowField& half, int w, int h,
                            const char* what = "fp16 vs fp32") {
  EXPECT_EQ(half.pixel_count(), exact.pixel_count());
  const Fp16Error r = flow_difference(exact, half);
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
