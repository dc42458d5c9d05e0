#pragma once
// Eight floats as one value, written once for every target through GCC's and Clang's vector
// extension: one AVX register with -mavx2, two NEON registers on aarch64, SSE pairs on x86
// builds without AVX. The Winograd transforms are expressed in it; the products' inner
// kernel has its own AVX2/FMA code beside a portable one (packed_gemm.cpp).
#include <cstring>

namespace neuflow::model::winograd {

using Float8 = float __attribute__((vector_size(32)));

inline Float8 load8(const float* p) {
  Float8 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

inline void store8(float* p, Float8 v) { std::memcpy(p, &v, sizeof v); }

inline Float8 splat8(float s) { return Float8{} + s; }

}  // namespace neuflow::model::winograd
