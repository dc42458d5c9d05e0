#include "dnnl/matrix_ops.hpp"
#include "ops/cpu_op.hpp"

namespace neuflow::model {

// NHWC tensors are token lists: each pixel a row of channels, rows a tensor's width apart.
std::unique_ptr<CpuOp> build_op(const graph::Linear<HostTensor>& op, OpBuild&) {
  return make_op([op](OpRun& pass) {
    Tensor& in = pass.tensors.nhwc(op.in.tensor);
    Tensor& out = pass.tensors.nhwc(op.out.tensor);
    const LinearWeights& w = *op.weights;
    const int tokens = static_cast<int>(in.pixels());
    matmul(pass.stream, {in.data.data() + op.in.channel, tokens, op.in.c, in.c},
           {w.weight.data(), w.out_features, w.in_features, w.in_features}, out.data.data() + op.out.channel, out.c,
           {.transpose_b = true, .bias = w.bias.empty() ? nullptr : w.bias.data(), .gelu = op.act == Activation::gelu});
    pass.stream.wait();
  });
}

}  // namespace neuflow::model
