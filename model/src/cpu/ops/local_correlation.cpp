#include <stdexcept>

#include "kernels/local_correlation.hpp"
#include "ops/cpu_op.hpp"

namespace neuflow::model {

std::unique_ptr<CpuOp> build_op(const graph::LocalCorrelation& op, OpBuild& b) {
  if (op.flow.channel != 0 || op.flow.c != b.tensors.desc(op.flow.tensor).c) {
    throw std::logic_error("the CPU's local correlation reads a flow tensor of its own");
  }
  return make_op([op](OpRun& pass) {
    TensorStore& t = pass.tensors;
    local_correlation(t.slice(op.f0), t.slice(op.f1), t.nhwc(op.flow.tensor), t.nhwc(op.out.tensor), op.out.channel);
  });
}

}  // namespace neuflow::model
