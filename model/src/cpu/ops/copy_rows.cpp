#include <algorithm>

#include "ops/cpu_op.hpp"

namespace neuflow::model {

// NHWC rows are contiguous runs of pixels: each pixel's channels copied.
std::unique_ptr<CpuOp> build_op(const graph::CopyRows& op, OpBuild&) {
  return make_op([op](OpRun& pass) {
    const Tensor& in = pass.tensors.nhwc(op.in.tensor);
    Tensor& out = pass.tensors.nhwc(op.out.tensor);
    const long pixels = static_cast<long>(op.rows) * in.w;
#pragma omp parallel for
    for (long i = 0; i < pixels; ++i) {
      const float* s = in.data.data() + (static_cast<std::size_t>(op.in_row) * in.w + i) * in.c + op.in.channel;
      float* d = out.data.data() + (static_cast<std::size_t>(op.out_row) * out.w + i) * out.c + op.out.channel;
      std::copy(s, s + op.in.c, d);
    }
  });
}

}  // namespace neuflow::model
