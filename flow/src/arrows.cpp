#include "neuflow/flow/arrows.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace neuflow::flow {

namespace {

// Clips the segment to [0, width-1] × [0, height-1] (Liang–Barsky), so that absurd vectors cost
// no more than the picture's diagonal and fit OpenCV's integer coordinates; false when nothing
// of it is inside.
bool clip_segment(double& xa, double& ya, double& xb, double& yb, int width, int height) {
  const double dx = xb - xa, dy = yb - ya;
  double t0 = 0, t1 = 1;
  const double p[4] = {-dx, dx, -dy, dy};
  const double q[4] = {xa, (width - 1) - xa, ya, (height - 1) - ya};
  for (int i = 0; i < 4; ++i) {
    if (p[i] == 0) {
      if (q[i] < 0) return false;  // parallel to this edge and outside it
      continue;
    }
    const double t = q[i] / p[i];
    if (p[i] < 0) {
      t0 = std::max(t0, t);
    } else {
      t1 = std::min(t1, t);
    }
    if (t0 > t1) return false;
  }
  xb = xa + t1 * dx;
  yb = ya + t1 * dy;
  xa = xa + t0 * dx;
  ya = ya + t0 * dy;
  return true;
}

// OpenCV's fixed-point coordinates: sub-pixel positions for anti-aliased lines.
constexpr int kShift = 4;
cv::Point fixed_point(double x, double y) {
  return {static_cast<int>(std::lround(x * (1 << kShift))), static_cast<int>(std::lround(y * (1 << kShift)))};
}

}  // namespace

void arrow_coverage(const FlowField& field, int width, int height, int spacing, double scale, double max_length,
                    std::vector<std::uint8_t>& coverage) {
  if (spacing < 1) throw std::invalid_argument("arrow spacing must be at least 1 pixel");
  if (field.width < 1 || field.height < 1 || width < 1 || height < 1) {
    throw std::invalid_argument("arrows need a non-empty field and picture");
  }
  coverage.assign(static_cast<std::size_t>(width) * height, 0);
  cv::Mat mask(height, width, CV_8UC1, coverage.data());
  for (int y = spacing / 2; y < height; y += spacing) {
    const int gy = std::min(static_cast<int>((y + 0.5) * field.height / height), field.height - 1);
    for (int x = spacing / 2; x < width; x += spacing) {
      const int gx = std::min(static_cast<int>((x + 0.5) * field.width / width), field.width - 1);
      double u = scale * field.u(gx, gy), v = scale * field.v(gx, gy);
      const double len = std::hypot(u, v);
      if (!(len >= 1.0) || !std::isfinite(len)) {  // under a pixel (or not finite): just the anchor
        mask.at<std::uint8_t>(y, x) = 255;
        continue;
      }
      if (len > max_length) {
        u *= max_length / len;
        v *= max_length / len;
      }
      double xa = x, ya = y, xb = x + u, yb = y + v;
      if (!clip_segment(xa, ya, xb, yb, width, height)) continue;
      // The head: a fixed share of the drawn length, at least 2 px, at most 0.4 of the spacing.
      const double drawn = std::hypot(xb - xa, yb - ya);
      const double head = std::clamp(0.3 * drawn, 2.0, std::max(2.0, 0.4 * spacing));
      cv::arrowedLine(mask, fixed_point(xa, ya), fixed_point(xb, yb), cv::Scalar(255), 1, cv::LINE_AA, kShift,
                      drawn > 0 ? std::min(1.0, head / drawn) : 0.0);
    }
  }
}

ArrowScale automatic_arrow_scale(int spacing, double max_flow) {
  return {spacing / std::max(max_flow, 1e-6), static_cast<double>(spacing)};
}

}  // namespace neuflow::flow
