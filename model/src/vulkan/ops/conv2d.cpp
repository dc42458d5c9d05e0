#include "vulkan/ops/record_op.hpp"

namespace neuflow::model::vulkan {

// The implicit-GEMM convolution (matmul.comp with IMPLICIT_CONV): one 64×64 tile of
// (pixels × output channels) per workgroup.
void record_op(Recorder& r, const graph::Conv2d<DeviceTensor>& op) {
  const DeviceConv& w = *op.weights;
  const View in = r.view(op.in), out = r.view(op.out);
  const View addend = op.addend ? r.view(*op.addend) : View{};
  const Conv2dParams p{in.c,
                       in.h,
                       in.w,
                       in.offset(),
                       out.c,
                       out.h,
                       out.w,
                       out.offset(),
                       w.kernel_h,
                       op.stride,
                       op.pad,
                       activation_code(op.act),
                       w.weight.offset,
                       w.bias.offset,
                       op.addend ? addend.offset() : -1,
                       1.f};
  const long long taps = static_cast<long long>(in.c) * w.kernel_h * w.kernel_w;
  const long long read = in.count() + taps * out.c + (w.bias.offset >= 0 ? out.c : 0) + (op.addend ? out.count() : 0);
  r.dispatch<Shader::conv2d>({&r.weights(), in.buffer, out.buffer, addend.buffer}, p,
                             {r.bytes(read), r.bytes(out.count()), taps * out.count()},
                             tiles(static_cast<long>(out.h) * out.w, "a convolution"), tiles(out.c, "a convolution"));
}

}  // namespace neuflow::model::vulkan
