#include "ops/cpu_op.hpp"

namespace neuflow::model {

std::unique_ptr<CpuOp> build_op(const graph::ChannelAffine<HostTensor>& op, OpBuild&) {
  return make_op([op](OpRun& pass) {
    Tensor& x = pass.tensors.nhwc(op.inout.tensor);
    const HostTensor &scale = *op.scale, &shift = *op.shift;
    for (std::size_t p = 0; p < x.pixels(); ++p) {
      float* v = x.data.data() + p * static_cast<std::size_t>(x.c) + op.inout.channel;
      for (int c = 0; c < op.inout.c; ++c)
        v[c] = v[c] * scale[static_cast<std::size_t>(c)] + shift[static_cast<std::size_t>(c)];
    }
  });
}

}  // namespace neuflow::model
