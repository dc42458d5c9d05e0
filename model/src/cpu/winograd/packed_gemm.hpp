#pragma once
// The products of one Winograd point for a block of tiles: C = A · B with A the tiles'
// transformed inputs (rows × depth, row-major), B the transformed filters packed in panels of
// `panel` output channels ([columns / panel][depth][panel]) and C row-major (rows × columns).
// rows is a multiple of the kernel's rows, columns of its panel. One thread; the caller
// blocks A to stay in L2.
namespace neuflow::model::winograd {

struct GemmKernel {
  const char* name;
  int rows;   // rows of A per inner kernel (tiles)
  int panel;  // columns per inner kernel (output channels)
  void (*run)(const float* a, const float* b_packed, float* c, int rows, int depth, int columns);
};

// The fastest kernel this CPU runs, chosen once at run time: AVX-512 (8 × 32) where the CPU
// has it, else AVX2/FMA (6 × 16) on x86, else a portable one (6 × 16) in Float8.
const GemmKernel& gemm_kernel();

// Each kernel this build has that this CPU runs, for tests that compare them.
const GemmKernel* const* gemm_kernels(int& count);

}  // namespace neuflow::model::winograd
