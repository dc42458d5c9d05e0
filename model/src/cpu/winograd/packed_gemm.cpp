#include "winograd/packed_gemm.hpp"

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "winograd/float8.hpp"

namespace neuflow::model::winograd {

namespace {

// Panels outside, so one panel of B (depth × panel floats) stays in L1 while the rows pass.
template <int Rows, int Panel, void (*Kernel)(const float*, int, const float*, float*, int)>
void panels(const float* a, const float* b_packed, float* c, int rows, int depth, int columns) {
  for (int p = 0; p < columns / Panel; ++p) {
    const float* b = b_packed + static_cast<long>(p) * depth * Panel;
    for (int r = 0; r < rows; r += Rows) {
      Kernel(a + static_cast<long>(r) * depth, depth, b, c + static_cast<long>(r) * columns + p * Panel, columns);
    }
  }
}

// Portable: 6 rows × 16 columns in Float8 (the compiler's vector code for the target).
void kernel_portable(const float* a, int depth, const float* b, float* c, int ldc) {
  Float8 acc[6][2] = {};
  for (int k = 0; k < depth; ++k) {
    const Float8 b0 = load8(b + 16 * k);
    const Float8 b1 = load8(b + 16 * k + 8);
    for (int r = 0; r < 6; ++r) {
      const Float8 x = splat8(a[r * depth + k]);
      acc[r][0] += x * b0;
      acc[r][1] += x * b1;
    }
  }
  for (int r = 0; r < 6; ++r) {
    store8(c + r * ldc, acc[r][0]);
    store8(c + r * ldc + 8, acc[r][1]);
  }
}

#if defined(__x86_64__)

// The accumulators are named variables, not an array, so the compiler keeps every one in a
// register across the depth loop (an array was spilled to the stack at each step).
#define NEUFLOW_ROW_AVX2(r)                                  \
  {                                                          \
    const __m256 x = _mm256_broadcast_ss(a + (r)*depth + k); \
    c##r##0 = _mm256_fmadd_ps(x, b0, c##r##0);               \
    c##r##1 = _mm256_fmadd_ps(x, b1, c##r##1);               \
  }
#define NEUFLOW_STORE_AVX2(r)             \
  _mm256_storeu_ps(c + (r)*ldc, c##r##0); \
  _mm256_storeu_ps(c + (r)*ldc + 8, c##r##1);

// AVX2/FMA: 6 rows × 16 columns in 12 registers; per step two panel loads, six broadcasts and
// twelve FMAs, so the FMA units set the pace.
__attribute__((target("avx2,fma"))) void kernel_avx2(const float* a, int depth, const float* b, float* c, int ldc) {
  __m256 c00 = _mm256_setzero_ps(), c01 = c00, c10 = c00, c11 = c00, c20 = c00, c21 = c00, c30 = c00, c31 = c00,
         c40 = c00, c41 = c00, c50 = c00, c51 = c00;
  for (int k = 0; k < depth; ++k) {
    const __m256 b0 = _mm256_loadu_ps(b + 16 * k);
    const __m256 b1 = _mm256_loadu_ps(b + 16 * k + 8);
    NEUFLOW_ROW_AVX2(0)
    NEUFLOW_ROW_AVX2(1) NEUFLOW_ROW_AVX2(2) NEUFLOW_ROW_AVX2(3) NEUFLOW_ROW_AVX2(4) NEUFLOW_ROW_AVX2(5)
  }
  NEUFLOW_STORE_AVX2(0)
  NEUFLOW_STORE_AVX2(1) NEUFLOW_STORE_AVX2(2) NEUFLOW_STORE_AVX2(3) NEUFLOW_STORE_AVX2(4) NEUFLOW_STORE_AVX2(5)
}

#define NEUFLOW_ROW_AVX512(r)                          \
  {                                                    \
    const __m512 x = _mm512_set1_ps(a[(r)*depth + k]); \
    c##r##0 = _mm512_fmadd_ps(x, b0, c##r##0);         \
    c##r##1 = _mm512_fmadd_ps(x, b1, c##r##1);         \
  }
#define NEUFLOW_STORE_AVX512(r)           \
  _mm512_storeu_ps(c + (r)*ldc, c##r##0); \
  _mm512_storeu_ps(c + (r)*ldc + 16, c##r##1);

// AVX-512: 8 rows × 32 columns in 16 of the 32 registers; per step two panel loads, eight
// broadcasts (folded into the FMAs) and sixteen FMAs.
__attribute__((target("avx512f"))) void kernel_avx512(const float* a, int depth, const float* b, float* c, int ldc) {
  __m512 c00 = _mm512_setzero_ps(), c01 = c00, c10 = c00, c11 = c00, c20 = c00, c21 = c00, c30 = c00, c31 = c00,
         c40 = c00, c41 = c00, c50 = c00, c51 = c00, c60 = c00, c61 = c00, c70 = c00, c71 = c00;
  for (int k = 0; k < depth; ++k) {
    const __m512 b0 = _mm512_loadu_ps(b + 32 * k);
    const __m512 b1 = _mm512_loadu_ps(b + 32 * k + 16);
    // The rows as a table: clang-format does not settle on one layout of them.
    // clang-format off
    NEUFLOW_ROW_AVX512(0) NEUFLOW_ROW_AVX512(1) NEUFLOW_ROW_AVX512(2) NEUFLOW_ROW_AVX512(3)
    NEUFLOW_ROW_AVX512(4) NEUFLOW_ROW_AVX512(5) NEUFLOW_ROW_AVX512(6) NEUFLOW_ROW_AVX512(7)
    // clang-format on
  }
  // clang-format off
  NEUFLOW_STORE_AVX512(0) NEUFLOW_STORE_AVX512(1) NEUFLOW_STORE_AVX512(2) NEUFLOW_STORE_AVX512(3)
  NEUFLOW_STORE_AVX512(4) NEUFLOW_STORE_AVX512(5) NEUFLOW_STORE_AVX512(6) NEUFLOW_STORE_AVX512(7)
  // clang-format on
}

#undef NEUFLOW_ROW_AVX2
#undef NEUFLOW_STORE_AVX2
#undef NEUFLOW_ROW_AVX512
#undef NEUFLOW_STORE_AVX512

constexpr GemmKernel kAvx2{"avx2", 6, 16, panels<6, 16, kernel_avx2>};
constexpr GemmKernel kAvx512{"avx512", 8, 32, panels<8, 32, kernel_avx512>};

#endif

constexpr GemmKernel kPortable{"portable", 6, 16, panels<6, 16, kernel_portable>};

struct Available {
  const GemmKernel* kernels[3];
  int count = 0;
  Available() {
#if defined(__x86_64__)
    if (__builtin_cpu_supports("avx512f")) kernels[count++] = &kAvx512;
    if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) kernels[count++] = &kAvx2;
#endif
    kernels[count++] = &kPortable;
  }
};

const Available& available() {
  static const Available a;
  return a;
}

}  // namespace

const GemmKernel& gemm_kernel() { return *available().kernels[0]; }

const GemmKernel* const* gemm_kernels(int& count) {
  count = available().count;
  return available().kernels;
}

}  // namespace neuflow::model::winograd
