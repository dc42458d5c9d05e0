#pragma once
// The products of one Winograd point for a block of tiles: C = A · B with A the tiles'
// transformed inputs (rows × depth, row-major), B the transformed filters packed in panels of
// 16 output channels ([columns / 16][depth][16]) and C row-major (rows × columns). rows is a
// multiple of kGemmRows, columns of kGemmPanel. One thread; the caller blocks A to stay in L2.
namespace neuflow::model::winograd {

constexpr int kGemmRows = 6;    // tiles per inner kernel: 6 × 2 accumulators + 2 panel loads
constexpr int kGemmPanel = 16;  // output channels per inner kernel, two 8-float registers

void packed_gemm(const float* a, const float* b_packed, float* c, int rows, int depth, int columns);

}  // namespace neuflow::model::winograd
