#include <algorithm>

#include "ops/cpu_op.hpp"

namespace neuflow::model {

namespace {
constexpr float kHiddenClamp = 4.f;
}  // namespace

std::unique_ptr<CpuOp> build_op(const graph::RefineUpdate& op, OpBuild&) {
  return make_op([op](OpRun& pass) {
    TensorStore& t = pass.tensors;
    const Tensor& update = t.nhwc(op.update.tensor);
    Tensor &hidden = t.nhwc(op.hidden.tensor), &flow_copy = t.nhwc(op.flow_copy.tensor), &flow = t.nhwc(op.flow.tensor);
    const int pixels = static_cast<int>(flow.pixels());
#pragma omp parallel for
    for (int p = 0; p < pixels; ++p) {
      const auto at = [p](const Tensor& x, int channel) {
        return static_cast<std::size_t>(p) * static_cast<std::size_t>(x.c) + static_cast<std::size_t>(channel);
      };
      const float* o = update.data.data() + at(update, op.update.channel);
      float* h = hidden.data.data() + at(hidden, op.hidden.channel);
      for (int c = 0; c < op.hidden.c; ++c) h[c] = std::clamp(o[2 + c], -kHiddenClamp, kHiddenClamp);
      float* f = flow.data.data() + at(flow, op.flow.channel);
      float* copy = flow_copy.data.data() + at(flow_copy, op.flow_copy.channel);
      for (int k = 0; k < 2; ++k) {
        f[k] += o[k];
        copy[k] = f[k];
      }
    }
  });
}

}  // namespace neuflow::model
