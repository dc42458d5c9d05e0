#include "kernels/layer_norm.hpp"
#include "ops/cpu_op.hpp"

namespace neuflow::model {

std::unique_ptr<CpuOp> build_op(const graph::LayerNorm<HostTensor>& op, OpBuild&) {
  return make_op([op](OpRun& pass) {
    TensorStore& t = pass.tensors;
    Tensor& in = t.nhwc(op.in.tensor);
    Tensor& out = t.nhwc(op.out.tensor);
    Tensor* residual = op.residual ? &t.nhwc(op.residual->tensor) : nullptr;
    layer_norm_rows({in.data.data() + op.in.channel, in.c}, {out.data.data() + op.out.channel, out.c},
                    residual ? RowsView{residual->data.data() + op.residual->channel, residual->c} : RowsView{},
                    static_cast<int>(in.pixels()), op.in.c, op.weights->gamma, op.weights->beta);
  });
}

}  // namespace neuflow::model
