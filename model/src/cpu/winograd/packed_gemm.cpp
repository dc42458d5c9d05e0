#include "winograd/packed_gemm.hpp"

#if defined(__AVX2__) && defined(__FMA__)
#include <immintrin.h>
#else
#include "winograd/float8.hpp"
#endif

namespace neuflow::model::winograd {

namespace {

#if defined(__AVX2__) && defined(__FMA__)

// 6 rows × 16 columns held in 12 registers over the whole depth: per step two panel loads,
// six broadcasts and twelve FMAs, so the FMA units, not the loads, set the pace.
void kernel_6x16(const float* a, int depth, const float* b, float* c, int ldc) {
  __m256 acc[kGemmRows][2];
  for (auto& row : acc) row[0] = row[1] = _mm256_setzero_ps();
  const float* a0 = a;
  const float* a1 = a + depth;
  const float* a2 = a + 2 * depth;
  const float* a3 = a + 3 * depth;
  const float* a4 = a + 4 * depth;
  const float* a5 = a + 5 * depth;
  for (int k = 0; k < depth; ++k) {
    const __m256 b0 = _mm256_loadu_ps(b + kGemmPanel * k);
    const __m256 b1 = _mm256_loadu_ps(b + kGemmPanel * k + 8);
    __m256 x = _mm256_broadcast_ss(a0 + k);
    acc[0][0] = _mm256_fmadd_ps(x, b0, acc[0][0]);
    acc[0][1] = _mm256_fmadd_ps(x, b1, acc[0][1]);
    x = _mm256_broadcast_ss(a1 + k);
    acc[1][0] = _mm256_fmadd_ps(x, b0, acc[1][0]);
    acc[1][1] = _mm256_fmadd_ps(x, b1, acc[1][1]);
    x = _mm256_broadcast_ss(a2 + k);
    acc[2][0] = _mm256_fmadd_ps(x, b0, acc[2][0]);
    acc[2][1] = _mm256_fmadd_ps(x, b1, acc[2][1]);
    x = _mm256_broadcast_ss(a3 + k);
    acc[3][0] = _mm256_fmadd_ps(x, b0, acc[3][0]);
    acc[3][1] = _mm256_fmadd_ps(x, b1, acc[3][1]);
    x = _mm256_broadcast_ss(a4 + k);
    acc[4][0] = _mm256_fmadd_ps(x, b0, acc[4][0]);
    acc[4][1] = _mm256_fmadd_ps(x, b1, acc[4][1]);
    x = _mm256_broadcast_ss(a5 + k);
    acc[5][0] = _mm256_fmadd_ps(x, b0, acc[5][0]);
    acc[5][1] = _mm256_fmadd_ps(x, b1, acc[5][1]);
  }
  for (int r = 0; r < kGemmRows; ++r) {
    _mm256_storeu_ps(c + r * ldc, acc[r][0]);
    _mm256_storeu_ps(c + r * ldc + 8, acc[r][1]);
  }
}

#else

// The same kernel for targets without AVX2/FMA, in the portable eight-float type.
void kernel_6x16(const float* a, int depth, const float* b, float* c, int ldc) {
  Float8 acc[kGemmRows][2] = {};
  for (int k = 0; k < depth; ++k) {
    const Float8 b0 = load8(b + kGemmPanel * k);
    const Float8 b1 = load8(b + kGemmPanel * k + 8);
    for (int r = 0; r < kGemmRows; ++r) {
      const Float8 x = splat8(a[r * depth + k]);
      acc[r][0] += x * b0;
      acc[r][1] += x * b1;
    }
  }
  for (int r = 0; r < kGemmRows; ++r) {
    store8(c + r * ldc, acc[r][0]);
    store8(c + r * ldc + 8, acc[r][1]);
  }
}

#endif

}  // namespace

void packed_gemm(const float* a, const float* b_packed, float* c, int rows, int depth, int columns) {
  // Panels outside, so one panel of B (depth × 16 floats) stays in L1 while the rows pass.
  for (int panel = 0; panel < columns / kGemmPanel; ++panel) {
    const float* b = b_packed + static_cast<long>(panel) * depth * kGemmPanel;
    for (int r = 0; r < rows; r += kGemmRows) {
      kernel_6x16(a + static_cast<long>(r) * depth, depth, b, c + static_cast<long>(r) * columns + panel * kGemmPanel,
                  columns);
    }
  }
}

}  // namespace neuflow::model::winograd
