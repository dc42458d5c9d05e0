#pragma once
// The colour wheel of the Middlebury flow tools (Baker et al., colorcode.cpp), also used by
// the Sintel tools, flow_vis and RAFT's flow_viz, so renderings look the way people expect:
// right = red, down = yellow, left = cyan, up = blue/violet, white = no motion.
#include <array>
#include <cstdint>

namespace neuflow::flow {

using Rgb8 = std::array<std::uint8_t, 3>;

// Segment lengths of the wheel: red→yellow, yellow→green, green→cyan, cyan→blue,
// blue→magenta, magenta→red.
inline constexpr int kWheelRY = 15, kWheelYG = 6, kWheelGC = 4, kWheelCB = 11, kWheelBM = 13, kWheelMR = 6;
inline constexpr int kWheelSize = kWheelRY + kWheelYG + kWheelGC + kWheelCB + kWheelBM + kWheelMR;

// The 55 wheel colours, RGB, index 0 = pure red.
const std::array<Rgb8, kWheelSize>& colorwheel();

// The colour of one flow vector already divided by the maximum magnitude (so |(u, v)| <= 1
// is in range). Hue follows the direction, saturation grows with the magnitude; a vector
// longer than 1 gets the fully saturated colour dimmed to 75%, as in the original code.
// Non-finite input gives black.
Rgb8 flow_color(double u, double v);

}  // namespace neuflow::flow
