#include <algorithm>

#include "dnnl/matrix_ops.hpp"
#include "ops/cpu_op.hpp"

namespace neuflow::model {

// In blocks of query rows, so memory stays O(L · block) instead of O(L²). Across frames, each
// frame's queries (its half of the tokens) against the other half's keys and values.
std::unique_ptr<CpuOp> build_op(const graph::Attention& op, OpBuild&) {
  return make_op([op](OpRun& pass) {
    TensorStore& t = pass.tensors;
    const Tensor &q = t.nhwc(op.q.tensor), &k = t.nhwc(op.k.tensor), &v = t.nhwc(op.v.tensor);
    Tensor& out = t.nhwc(op.out.tensor);
    float* scores = t.nhwc(op.scores).data.data();
    const int frames = op.across_frames ? 2 : 1;
    const int l = static_cast<int>(q.pixels()) / frames, dim = op.q.c;
    for (int f = 0; f < frames; ++f) {
      const std::size_t first_query = static_cast<std::size_t>(f) * l;
      const std::size_t first_key = op.across_frames ? static_cast<std::size_t>(1 - f) * l : 0;
      const float* qd = q.data.data() + first_query * q.c + op.q.channel;
      const float* kd = k.data.data() + first_key * k.c + op.k.channel;
      const float* vd = v.data.data() + first_key * v.c + op.v.channel;
      float* od = out.data.data() + first_query * out.c + op.out.channel;
      for (int r0 = 0; r0 < l; r0 += op.block_rows) {
        const int n = std::min(op.block_rows, l - r0);
        matmul(pass.stream, {qd + static_cast<std::size_t>(r0) * q.c, n, dim, q.c}, {kd, l, dim, k.c}, scores, l,
               {.transpose_b = true});
        softmax_rows(pass.stream, scores, n, l);
        matmul(pass.stream, {scores, n, l, l}, {vd, l, op.v.c, v.c}, od + static_cast<std::size_t>(r0) * out.c, out.c);
      }
    }
    pass.stream.wait();
  });
}

}  // namespace neuflow::model
