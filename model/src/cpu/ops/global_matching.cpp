#include <algorithm>
#include <cmath>

#include "dnnl/matrix_ops.hpp"
#include "ops/cpu_op.hpp"

namespace neuflow::model {

// softmax(f0 f1ᵀ / √c) in blocks of rows, each block's correspondences its rows times the grid
// (NHWC: each pixel's (x, y)); the flow is correspondence - grid.
std::unique_ptr<CpuOp> build_op(const graph::GlobalMatching& op, OpBuild&) {
  return make_op([op](OpRun& pass) {
    TensorStore& t = pass.tensors;
    const Tensor &f0 = t.nhwc(op.f0.tensor), &f1 = t.nhwc(op.f1.tensor), &grid = t.nhwc(op.grid.tensor);
    Tensor &out = t.nhwc(op.out.tensor), &correspondence = t.nhwc(op.correspondence);
    float* scores = t.nhwc(op.scores).data.data();
    const int l = static_cast<int>(f0.pixels()), c = op.f0.c;
    const float alpha = 1.f / std::sqrt(static_cast<float>(c));
    const float* a = f0.data.data() + op.f0.channel;
    for (int r0 = 0; r0 < l; r0 += op.block_rows) {
      const int n = std::min(op.block_rows, l - r0);
      matmul(pass.stream, {a + static_cast<std::size_t>(r0) * f0.c, n, c, f0.c},
             {f1.data.data() + op.f1.channel, l, c, f1.c}, scores, l, {.transpose_b = true, .alpha = alpha});
      softmax_rows(pass.stream, scores, n, l);
      matmul(pass.stream, {scores, n, l, l}, {grid.data.data() + op.grid.channel, l, 2, grid.c},
             correspondence.data.data() + static_cast<std::size_t>(r0) * correspondence.c, correspondence.c);
    }
    pass.stream.wait();
    for (std::size_t p = 0; p < out.pixels(); ++p) {
      for (int k = 0; k < 2; ++k) {
        out.data[p * static_cast<std::size_t>(out.c) + static_cast<std::size_t>(op.out.channel + k)] =
            correspondence.data[p * static_cast<std::size_t>(correspondence.c) + static_cast<std::size_t>(k)] -
            grid.data[p * static_cast<std::size_t>(grid.c) + static_cast<std::size_t>(op.grid.channel + k)];
      }
    }
  });
}

}  // namespace neuflow::model
