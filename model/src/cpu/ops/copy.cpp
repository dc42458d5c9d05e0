#include "kernels/feature_ops.hpp"
#include "ops/cpu_op.hpp"

namespace neuflow::model {

std::unique_ptr<CpuOp> build_op(const graph::Copy& op, OpBuild&) {
  return make_op([op](OpRun& pass) {
    copy_channels(pass.tensors.slice(op.in), pass.tensors.nhwc(op.out.tensor), op.out.channel);
  });
}

}  // namespace neuflow::model
