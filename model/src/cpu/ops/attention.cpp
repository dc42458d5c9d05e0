#include <algorithm>

#include "dnnl/matrix_ops.hpp"
#include "ops/cpu_op.hpp"

namespace neuflow::model {

// In blocks of query rows, so memory stays O(L · block) instead of O(L²).
std::unique_ptr<CpuOp> build_op(const graph::Attention& op, OpBuild&) {
  return make_op([op](OpRun& pass) {
    TensorStore& t = pass.tensors;
    const Tensor &q = t.nhwc(op.q.tensor), &k = t.nhwc(op.k.tensor), &v = t.nhwc(op.v.tensor);
    Tensor& out = t.nhwc(op.out.tensor);
    float* scores = t.nhwc(op.scores).data.data();
    const int l = static_cast<int>(q.pixels()), dim = op.q.c;
    const float* qd = q.data.data() + op.q.channel;
    for (int r0 = 0; r0 < l; r0 += op.block_rows) {
      const int n = std::min(op.block_rows, l - r0);
      matmul(pass.stream, {qd + static_cast<std::size_t>(r0) * q.c, n, dim, q.c},
             {k.data.data() + op.k.channel, l, dim, k.c}, scores, l, {.transpose_b = true});
      softmax_rows(pass.stream, scores, n, l);
      matmul(pass.stream, {scores, n, l, l}, {v.data.data() + op.v.channel, l, op.v.c, v.c},
             out.data.data() + static_cast<std::size_t>(r0) * out.c + op.out.channel, out.c);
    }
    pass.stream.wait();
  });
}

}  // namespace neuflow::model
