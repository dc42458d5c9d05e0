#include <stdexcept>

#include "kernels/feature_ops.hpp"
#include "ops/cpu_op.hpp"

namespace neuflow::model {

std::unique_ptr<CpuOp> build_op(const graph::Resample& op, OpBuild&) {
  if (!(op.factor == 2 || (op.factor == 1 && op.scale == 1.f))) {
    throw std::logic_error("the CPU resamples by 2, or copies by 1 without scaling");
  }
  return make_op([op](OpRun& pass) {
    const ChannelSlice in = pass.tensors.slice(op.in);
    Tensor& out = pass.tensors.nhwc(op.out.tensor);
    if (op.factor == 1) {
      copy_channels(in, out, op.out.channel, op.relu);
    } else {
      upsample_nearest_2x(in, out, op.out.channel, op.scale, op.relu);
    }
  });
}

}  // namespace neuflow::model
