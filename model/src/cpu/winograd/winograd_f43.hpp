#pragma once
// Winograd's minimal filtering F(4×4, 3×3) (Lavin & Gray, "Fast Algorithms for Convolutional
// Neural Networks", 2016): a 4×4 tile of a stride-1 3×3 convolution's output from the 6×6
// input tile around it in 36 element-wise products instead of 144 multiply-adds per channel
// pair: Y = Aᵀ [(G g Gᵀ) ⊙ (Bᵀ d B)] A. The points ξ = 6·i + j of a transformed tile are laid
// out row-major. Each transform is separable: the 1-D form runs over columns, then rows.
#include "winograd/float8.hpp"

namespace neuflow::model::winograd {

constexpr int kOutputTile = 4;
constexpr int kInputTile = 6;
constexpr int kPoints = kInputTile * kInputTile;

// A 3×3 filter (row-major) to its 36 points G g Gᵀ, computed in double.
void transform_filter(const float* filter, float* points);

namespace detail {

// Bᵀ applied to six values at stride `s` of `d`, written at stride `s` of `r`.
inline void input_1d(const Float8* d, Float8* r, int s) {
  const Float8 d0 = d[0], d1 = d[s], d2 = d[2 * s], d3 = d[3 * s], d4 = d[4 * s], d5 = d[5 * s];
  r[0] = 4.f * d0 - 5.f * d2 + d4;
  r[s] = d3 + d4 - 4.f * (d1 + d2);
  r[2 * s] = d4 - d3 + 4.f * (d1 - d2);
  r[3 * s] = d4 - d2 + 2.f * (d3 - d1);
  r[4 * s] = d4 - d2 + 2.f * (d1 - d3);
  r[5 * s] = 4.f * d1 - 5.f * d3 + d5;
}

// Aᵀ applied to six values at stride `s` of `m`, four results at stride `rs` of `o`.
inline void output_1d(const Float8* m, Float8* o, int s, int rs) {
  const Float8 m1 = m[s], m2 = m[2 * s], m3 = m[3 * s], m4 = m[4 * s];
  const Float8 sum12 = m1 + m2, diff12 = m1 - m2, sum34 = m3 + m4, diff34 = m3 - m4;
  o[0] = m[0] + sum12 + sum34;
  o[rs] = diff12 + 2.f * diff34;
  o[2 * rs] = sum12 + 4.f * sum34;
  o[3 * rs] = diff12 + 8.f * diff34 + m[5 * s];
}

}  // namespace detail

// A 6×6 input tile of eight channels (row-major) to its 36 points Bᵀ d B.
inline void transform_input(const Float8* d, Float8* points) {
  Float8 t[kPoints];
  for (int j = 0; j < kInputTile; ++j) detail::input_1d(d + j, t + j, kInputTile);
  for (int i = 0; i < kInputTile; ++i) detail::input_1d(t + kInputTile * i, points + kInputTile * i, 1);
}

// 36 points of products (eight channels) to the 4×4 output tile Aᵀ m A (row-major).
inline void transform_output(const Float8* points, Float8* out) {
  Float8 t[kOutputTile * kInputTile];  // 4 rows × 6 columns
  for (int j = 0; j < kInputTile; ++j) detail::output_1d(points + j, t + j, kInputTile, kInputTile);
  for (int i = 0; i < kOutputTile; ++i) detail::output_1d(t + kInputTile * i, out + kOutputTile * i, 1, 1);
}

}  // namespace neuflow::model::winograd
