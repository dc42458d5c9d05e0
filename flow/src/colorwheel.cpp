#include "neuflow/flow/colorwheel.hpp"

#include <cmath>
#include <numbers>

#include "wheel_color.hpp"

namespace neuflow::flow {

namespace {

std::array<Rgb8, kWheelSize> make_colorwheel() {
  std::array<Rgb8, kWheelSize> wheel{};
  int k = 0;
  // Integer division as in colorcode.cpp (= floor in flow_vis), so the tables agree exactly.
  auto ramp = [](int i, int n) { return static_cast<std::uint8_t>(255 * i / n); };
  auto fall = [](int i, int n) { return static_cast<std::uint8_t>(255 - 255 * i / n); };
  for (int i = 0; i < kWheelRY; ++i) wheel[static_cast<std::size_t>(k++)] = {255, ramp(i, kWheelRY), 0};
  for (int i = 0; i < kWheelYG; ++i) wheel[static_cast<std::size_t>(k++)] = {fall(i, kWheelYG), 255, 0};
  for (int i = 0; i < kWheelGC; ++i) wheel[static_cast<std::size_t>(k++)] = {0, 255, ramp(i, kWheelGC)};
  for (int i = 0; i < kWheelCB; ++i) wheel[static_cast<std::size_t>(k++)] = {0, fall(i, kWheelCB), 255};
  for (int i = 0; i < kWheelBM; ++i) wheel[static_cast<std::size_t>(k++)] = {ramp(i, kWheelBM), 0, 255};
  for (int i = 0; i < kWheelMR; ++i) wheel[static_cast<std::size_t>(k++)] = {255, 0, fall(i, kWheelMR)};
  return wheel;
}

}  // namespace

const std::array<Rgb8, kWheelSize>& colorwheel() {
  static const auto wheel = make_colorwheel();
  return wheel;
}

Rgb8 flow_color(double u, double v) {
  if (!std::isfinite(u) || !std::isfinite(v)) return {0, 0, 0};
  return detail::wheel_color(u, v, std::sqrt(u * u + v * v));
}

Rgb8 detail::wheel_color(double u, double v, double rad) {
  const auto& wheel = colorwheel();
  // The angle is measured from the negative axes, so that flow to the right (u > 0, v = 0,
  // hence -v = -0.0 and atan2 = -pi) lands on index 0, red, as in the original.
  const double a = std::atan2(-v, -u) / std::numbers::pi;
  const double fk = (a + 1.0) / 2.0 * (kWheelSize - 1);
  int k0 = static_cast<int>(fk);
  if (k0 < 0) k0 = 0;
  if (k0 > kWheelSize - 1) k0 = kWheelSize - 1;
  const int k1 = (k0 + 1) % kWheelSize;
  const double f = fk - k0;
  Rgb8 out{};
  for (std::size_t b = 0; b < 3; ++b) {
    const double col0 = wheel[static_cast<std::size_t>(k0)][b] / 255.0;
    const double col1 = wheel[static_cast<std::size_t>(k1)][b] / 255.0;
    double col = (1 - f) * col0 + f * col1;
    if (rad <= 1) {
      col = 1 - rad * (1 - col);  // towards white as the magnitude shrinks
    } else {
      col *= 0.75;  // beyond the maximum: dimmed, so saturation outliers stand out
    }
    out[b] = static_cast<std::uint8_t>(255.0 * col);
  }
  return out;
}

}  // namespace neuflow::flow
