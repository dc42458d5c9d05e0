#pragma once
// Winograd F(6×6, 3×3): a 6×6 output tile from the 8×8 input tile around it in 64 products
// instead of 324 multiply-adds per channel pair (1.27× fewer than F(4×4, 3×3) per output,
// and, at the network's 1/8 and 1/16 sizes, tiles that divide the image with less waste),
// with the interpolation points 0, ±1, ±2, ±1/2, ∞. Its larger transform coefficients
// (up to 32) cost about ten times F(4×4)'s rounding error, so the plan uses it only where that
// stays within the error budget (dnnl/conv_op.cpp). The same conventions as winograd_f43.hpp;
// the forms of the 1-D transforms are those of ncnn's and Lavin's wincnn.
#include "winograd/float8.hpp"
#include "winograd/tile_sizes.hpp"

namespace neuflow::model::winograd {

struct F63 : TileSizes<6> {
  // Bᵀ applied to eight values at stride `s` of `d`, written at stride `s` of `r`.
  static void input_1d(const Float8* d, Float8* r, int s) {
    const Float8 d0 = d[0], d1 = d[s], d2 = d[2 * s], d3 = d[3 * s], d4 = d[4 * s], d5 = d[5 * s], d6 = d[6 * s],
                 d7 = d[7 * s];
    r[0] = d0 - d6 + 5.25f * (d4 - d2);
    r[7 * s] = d7 - d1 + 5.25f * (d3 - d5);
    const Float8 t1 = d2 + d6 - 4.25f * d4, t2 = d1 + d5 - 4.25f * d3;
    r[s] = t1 + t2;
    r[2 * s] = t1 - t2;
    const Float8 t3 = d6 + 0.25f * d2 - 1.25f * d4, t4 = 0.5f * d1 - 2.5f * d3 + 2.f * d5;
    r[3 * s] = t3 + t4;
    r[4 * s] = t3 - t4;
    const Float8 t5 = d6 + 4.f * d2 - 5.f * d4, t6 = 2.f * d1 - 2.5f * d3 + 0.5f * d5;
    r[5 * s] = t5 + t6;
    r[6 * s] = t5 - t6;
  }

  // Aᵀ applied to eight values at stride `s` of `m`, six results at stride `rs` of `o`.
  static void output_1d(const Float8* m, Float8* o, int s, int rs) {
    const Float8 sum12 = m[s] + m[2 * s], diff12 = m[s] - m[2 * s];
    const Float8 sum34 = m[3 * s] + m[4 * s], diff34 = m[3 * s] - m[4 * s];
    const Float8 sum56 = m[5 * s] + m[6 * s], diff56 = m[5 * s] - m[6 * s];
    o[0] = m[0] + sum12 + sum34 + sum56;
    o[rs] = diff12 + 2.f * diff34 + 0.5f * diff56;
    o[2 * rs] = sum12 + 4.f * sum34 + 0.25f * sum56;
    o[3 * rs] = diff12 + 8.f * diff34 + 0.125f * diff56;
    o[4 * rs] = sum12 + 16.f * sum34 + 0.0625f * sum56;
    o[5 * rs] = diff12 + 32.f * diff34 + 0.03125f * diff56 + m[7 * s];
  }

  // G (8×3) applied to three values at stride `s`, eight results at stride `rs`.
  static void filter_1d(const double* g, double* r, int s, int rs) {
    const double a = g[0], b = g[s], c = g[2 * s];
    r[0] = a;
    r[rs] = -2.0 / 9 * (a + b + c);
    r[2 * rs] = -2.0 / 9 * (a - b + c);
    r[3 * rs] = a / 90 + b / 45 + 2 * c / 45;
    r[4 * rs] = a / 90 - b / 45 + 2 * c / 45;
    r[5 * rs] = 32 * a / 45 + 16 * b / 45 + 8 * c / 45;
    r[6 * rs] = 32 * a / 45 - 16 * b / 45 + 8 * c / 45;
    r[7 * rs] = c;
  }
};

}  // namespace neuflow::model::winograd
