#pragma once
#include "neuflow/flow/colorwheel.hpp"

namespace neuflow::flow::detail {

// flow_color with the normalized radius supplied by the caller: the hue comes from the
// direction of (u, v) (any scale), the saturation from rad. visualize_flow passes
// |flow| / max so that the largest vector gets exactly 1, not 1 + rounding (which would
// dim it as out of range).
Rgb8 wheel_color(double u, double v, double rad);

}  // namespace neuflow::flow::detail
