#include "kernels/local_correlation.hpp"

#include <cmath>

#if defined(__AVX2__) && defined(__FMA__)
#include <immintrin.h>
#endif
#include <stdexcept>

namespace neuflow::model {

namespace {

float dot(const float* a, const float* b, int n) {
  float s = 0.f;
#pragma omp simd reduction(+ : s)
  for (int i = 0; i < n; ++i) s += a[i] * b[i];
  return s;
}

#if defined(__AVX2__) && defined(__FMA__)
float horizontal_sum(__m256 v) {
  __m128 x = _mm_add_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps(v, 1));
  x = _mm_add_ps(x, _mm_movehl_ps(x, x));
  x = _mm_add_ss(x, _mm_movehdup_ps(x));
  return _mm_cvtss_f32(x);
}

// Dot products of `a` with five consecutive pixels b, b + stride, ...: each chunk of `a` is
// loaded once for five FMAs. n must be a multiple of 8.
void dot5(const float* a, const float* b, int stride, int n, float* out) {
  __m256 acc0 = _mm256_setzero_ps(), acc1 = _mm256_setzero_ps(), acc2 = _mm256_setzero_ps();
  __m256 acc3 = _mm256_setzero_ps(), acc4 = _mm256_setzero_ps();
  for (int i = 0; i < n; i += 8) {
    const __m256 va = _mm256_loadu_ps(a + i);
    acc0 = _mm256_fmadd_ps(va, _mm256_loadu_ps(b + i), acc0);
    acc1 = _mm256_fmadd_ps(va, _mm256_loadu_ps(b + stride + i), acc1);
    acc2 = _mm256_fmadd_ps(va, _mm256_loadu_ps(b + 2 * stride + i), acc2);
    acc3 = _mm256_fmadd_ps(va, _mm256_loadu_ps(b + 3 * stride + i), acc3);
    acc4 = _mm256_fmadd_ps(va, _mm256_loadu_ps(b + 4 * stride + i), acc4);
  }
  out[0] = horizontal_sum(acc0);
  out[1] = horizontal_sum(acc1);
  out[2] = horizontal_sum(acc2);
  out[3] = horizontal_sum(acc3);
  out[4] = horizontal_sum(acc4);
}
constexpr bool kHaveDot5 = true;
#else
void dot5(const float* a, const float* b, int stride, int n, float* out) {
  for (int k = 0; k < 5; ++k) out[k] = dot(a, b + k * stride, n);
}
constexpr bool kHaveDot5 = false;
#endif

}  // namespace

void local_correlation(const ChannelSlice& f0, const ChannelSlice& f1, const Tensor& flow, Tensor& out,
                       int out_offset) {
  const int h = f0.h(), w = f0.w(), channels = f0.channels;
  if (f1.h() != h || f1.w() != w || f1.channels != channels || flow.h != h || flow.w != w || flow.c != 2 ||
      out.h != h || out.w != w || out_offset + kCorrWindow * kCorrWindow > out.c) {
    throw std::logic_error("local_correlation: shapes do not fit");
  }
  const float norm = 1.f / std::sqrt(static_cast<float>(channels));
  constexpr int n = kCorrWindow + 1;  // integer neighbours per axis, two groups of five

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
      // Row by row of frame 1: the ten neighbours of a row are consecutive pixels in memory.
      for (int j = 0; j < n; ++j) {
        const int qy = by + j;
        if (qy < 0 || qy >= h) {
          for (int i = 0; i < n; ++i) d[i][j] = 0.f;
          continue;
        }
        int i = 0;
        for (; i < n; i += 5) {
          float five[5];
          if (kHaveDot5 && channels % 8 == 0 && bx + i >= 0 && bx + i + 5 <= w) {
            dot5(a, f1.pixel(qy, bx + i), f1.stride(), channels, five);
          } else {  // at the frame's border
            for (int k = 0; k < 5; ++k) {
              const int qx = bx + i + k;
              five[k] = (qx >= 0 && qx < w) ? dot(a, f1.pixel(qy, qx), channels) : 0.f;
            }
          }
          for (int k = 0; k < 5; ++k) d[i + k][j] = five[k] * norm;
        }
      }
      const float w00 = (1 - ax) * (1 - ay), w10 = ax * (1 - ay), w01 = (1 - ax) * ay, w11 = ax * ay;
      for (int i = 0; i < kCorrWindow; ++i) {
        for (int j = 0; j < kCorrWindow; ++j) {
          o[i * kCorrWindow + j] = w00 * d[i][j] + w10 * d[i + 1][j] + w01 * d[i][j + 1] + w11 * d[i + 1][j + 1];
        }
      }
    }
  }
}

}  // namespace neuflow::model
