#include "ops/local_correlation.hpp"

#include <cmath>
#include <stdexcept>

namespace neuflow::model {

namespace {

float dot(const float* a, const float* b, int n) {
  float acc[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  int i = 0;
  for (; i + 8 <= n; i += 8) {
    for (int k = 0; k < 8; ++k) acc[k] += a[i + k] * b[i + k];
  }
  float s = 0.f;
  for (; i < n; ++i) s += a[i] * b[i];
  for (float v : acc) s += v;
  return s;
}

}  // namespace

void local_correlation(const ChannelSlice& f0, const ChannelSlice& f1, const Tensor& flow, Tensor& out,
                       int out_offset) {
  const int h = f0.h(), w = f0.w(), channels = f0.channels;
  if (f1.h() != h || f1.w() != w || f1.channels != channels || flow.h != h || flow.w != w || flow.c != 2 ||
      out.h != h || out.w != w || out_offset + kCorrWindow * kCorrWindow > out.c) {
    throw std::logic_error("local_correlation: shapes do not fit");
  }
  const float norm = 1.f / std::sqrt(static_cast<float>(channels));
  constexpr int n = kCorrWindow + 1;  // integer neighbours per axis

#pragma omp parallel for
  for (int y = 0; y < h; ++y) {
    float d[n][n];  // d[i][j]: neighbour at (bx - 4 + i, by - 4 + j)
    for (int x = 0; x < w; ++x) {
      const float* fl = flow.pixel(y, x);
      const float px = static_cast<float>(x) + fl[0];
      const float py = static_cast<float>(y) + fl[1];
      const float fx0 = std::floor(px), fy0 = std::floor(py);
      const float ax = px - fx0, ay = py - fy0;
      float* o = out.pixel(y, x) + out_offset;
      // Far outside the frame every sample is zero; avoid int overflow on absurd flows.
      if (!(std::fabs(px) < 1e6f && std::fabs(py) < 1e6f)) {
        for (int k = 0; k < kCorrWindow * kCorrWindow; ++k) o[k] = 0.f;
        continue;
      }
      const int bx = static_cast<int>(fx0) - kCorrRadius, by = static_cast<int>(fy0) - kCorrRadius;
      const float* a = f0.pixel(y, x);
      for (int i = 0; i < n; ++i) {
        const int qx = bx + i;
        for (int j = 0; j < n; ++j) {
          const int qy = by + j;
          d[i][j] = (qx >= 0 && qx < w && qy >= 0 && qy < h) ? dot(a, f1.pixel(qy, qx), channels) * norm : 0.f;
        }
      }
      const float w00 = (1 - ax) * (1 - ay), w10 = ax * (1 - ay), w01 = (1 - ax) * ay, w11 = ax * ay;
      for (int i = 0; i < kCorrWindow; ++i) {
        for (int j = 0; j < kCorrWindow; ++j) {
          o[i * kCorrWindow + j] =
              w00 * d[i][j] + w10 * d[i + 1][j] + w01 * d[i][j + 1] + w11 * d[i + 1][j + 1];
        }
      }
    }
  }
}

}  // namespace neuflow::model
