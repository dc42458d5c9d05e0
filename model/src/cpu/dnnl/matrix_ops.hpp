#pragma once
// Row-major matrix products and row softmax on oneDNN. Primitives are looked up in
// oneDNN's primitive cache on each call, so repeated shapes cost no re-creation.
#include <dnnl.hpp>

#include <cstddef>

namespace neuflow::model {

struct MatrixView {
  const float* data;
  int rows;
  int cols;
  int ld;  // elements between consecutive rows
};

// C[M,N] = alpha · A[M,K] · op(B) (+ bias[N]), where op(B) = B ([K,N]) or, with transpose_b,
// B^T for B stored as [N,K]. C is row-major with leading dimension ldc.
// alpha scales the product (only without bias); gelu applies the exact GELU to the result.
struct MatmulOptions {
  bool transpose_b = false;
  const float* bias = nullptr;
  float alpha = 1.f;
  bool gelu = false;
};
void matmul(dnnl::stream& stream, MatrixView a, MatrixView b, float* c, int ldc, const MatmulOptions& options = {});

// In place: every row of the [rows, cols] contiguous matrix becomes its softmax.
void softmax_rows(dnnl::stream& stream, float* data, int rows, int cols);

// In place: x = exp(x) over `count` contiguous values.
void exp_in_place(dnnl::stream& stream, float* data, std::size_t count);

}  // namespace neuflow::model
