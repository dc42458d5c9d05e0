#pragma once
// Winograd's minimal filtering F(4×4, 3×3) (Lavin & Gray, "Fast Algorithms for Convolutional
// Neural Networks", 2016): a 4×4 tile of a stride-1 3×3 convolution's output from the 6×6
// input tile around it in 36 element-wise products instead of 144 multiply-adds per channel
// pair: Y = Aᵀ [(G g Gᵀ) ⊙ (Bᵀ d B)] A, with the interpolation points 0, ±1, ±2, ∞. The
// points ξ = 6·i + j of a transformed tile are laid out row-major. Each transform is
// separable: the 1-D form runs over columns, then rows.
#include "winograd/float8.hpp"
#include "winograd/tile_sizes.hpp"

namespace neuflow::model::winograd {

struct F43 : TileSizes<4> {
  // Bᵀ applied to six values at stride `s` of `d`, written at stride `s` of `r`.
  static void input_1d(const Float8* d, Float8* r, int s) {
    const Float8 d0 = d[0], d1 = d[s], d2 = d[2 * s], d3 = d[3 * s], d4 = d[4 * s], d5 = d[5 * s];
    r[0] = 4.f * d0 - 5.f * d2 + d4;
    r[s] = d3 + d4 - 4.f * (d1 + d2);
    r[2 * s] = d4 - d3 + 4.f * (d1 - d2);
    r[3 * s] = d4 - d2 + 2.f * (d3 - d1);
    r[4 * s] = d4 - d2 + 2.f * (d1 - d3);
    r[5 * s] = 4.f * d1 - 5.f * d3 + d5;
  }

  // Aᵀ applied to six values at stride `s` of `m`, four results at stride `rs` of `o`.
  static void output_1d(const Float8* m, Float8* o, int s, int rs) {
    const Float8 m1 = m[s], m2 = m[2 * s], m3 = m[3 * s], m4 = m[4 * s];
    const Float8 sum12 = m1 + m2, diff12 = m1 - m2, sum34 = m3 + m4, diff34 = m3 - m4;
    o[0] = m[0] + sum12 + sum34;
    o[rs] = diff12 + 2.f * diff34;
    o[2 * rs] = sum12 + 4.f * sum34;
    o[3 * rs] = diff12 + 8.f * diff34 + m[5 * s];
  }

  // G (6×3) applied to three values at stride `s`, six results at stride `rs`.
  static void filter_1d(const double* g, double* r, int s, int rs) {
    const double a = g[0], b = g[s], c = g[2 * s];
    r[0] = a / 4;
    r[rs] = -(a + b + c) / 6;
    r[2 * rs] = -(a - b + c) / 6;
    r[3 * rs] = a / 24 + b / 12 + c / 6;
    r[4 * rs] = a / 24 - b / 12 + c / 6;
    r[5 * rs] = c;
  }
};

}  // namespace neuflow::model::winograd
