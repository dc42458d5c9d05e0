#include <algorithm>

#include "ops/cpu_op.hpp"

namespace neuflow::model {

std::unique_ptr<CpuOp> build_op(const graph::Zero& op, OpBuild&) {
  return make_op([op](OpRun& pass) {
    Tensor& t = pass.tensors.nhwc(op.out.tensor);
    for (std::size_t p = 0; p < t.pixels(); ++p) {
      std::fill_n(t.data.data() + p * static_cast<std::size_t>(t.c) + op.out.channel, op.out.c, 0.f);
    }
  });
}

}  // namespace neuflow::model
