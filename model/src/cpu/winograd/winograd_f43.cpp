#include "winograd/winograd_f43.hpp"

namespace neuflow::model::winograd {

namespace {

// G (6×3) applied to three values at stride `s`, six results at stride `rs`.
void filter_1d(const double* g, double* r, int s, int rs) {
  const double a = g[0], b = g[s], c = g[2 * s];
  r[0] = a / 4;
  r[rs] = -(a + b + c) / 6;
  r[2 * rs] = -(a - b + c) / 6;
  r[3 * rs] = a / 24 + b / 12 + c / 6;
  r[4 * rs] = a / 24 - b / 12 + c / 6;
  r[5 * rs] = c;
}

}  // namespace

void transform_filter(const float* filter, float* points) {
  double g[9], t[kInputTile * 3], p[kPoints];
  for (int i = 0; i < 9; ++i) g[i] = filter[i];
  for (int j = 0; j < 3; ++j) filter_1d(g + j, t + j, 3, 3);                      // 6 rows × 3
  for (int i = 0; i < kInputTile; ++i) filter_1d(t + 3 * i, p + kInputTile * i, 1, 1);  // 6 × 6
  for (int i = 0; i < kPoints; ++i) points[i] = static_cast<float>(p[i]);
}

}  // namespace neuflow::model::winograd
