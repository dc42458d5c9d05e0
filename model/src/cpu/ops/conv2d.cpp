#include <optional>
#include <stdexcept>

#include "dnnl/context.hpp"
#include "dnnl/conv_op.hpp"
#include "ops/cpu_op.hpp"

namespace neuflow::model {

namespace {

// A convolution into a whole tensor (in its own layout, or NHWC where other ops read it), or
// into a channel range of an NHWC tensor (a concatenation), through its own output and a
// reorder.
class Conv2dOp final : public CpuOp {
 public:
  Conv2dOp(const graph::Conv2d<HostTensor>& op, OpBuild& b) : op_(op) {
    TensorStore& t = b.tensors;
    const graph::TensorDesc& out = t.desc(op.out.tensor);
    if (op.in.channel != 0 || op.in.c != t.desc(op.in.tensor).c) {
      throw std::logic_error("the CPU's " + op.layer + " reads part of a tensor");
    }
    whole_ = op.out.channel == 0 && op.out.c == out.c;
    std::optional<dnnl::memory::desc> layout;
    if (op.addend) {
      layout = t.layout(op.addend->tensor);  // the sum is computed in the addend's layout
    } else if (whole_ && !t.blocked(op.out.tensor)) {
      layout = nhwc_desc(out.h, out.w, out.c);
    }
    const ConvParams params{op.stride, op.pad, op.act, op.addend.has_value(), b.repeated};
    conv_.emplace(*op.weights, params, t.layout(op.in.tensor), b.scratch, layout, /*own_output=*/!whole_);
    if (whole_ && t.blocked(op.out.tensor)) t.set_layout(op.out.tensor, conv_->output_desc());
    if (!whole_) {
      slice_ = nhwc_desc(out.h, out.w, out.c).submemory_desc({1, op.out.c, out.h, out.w}, {0, op.out.channel, 0, 0});
      to_slice_ =
          dnnl::reorder(dnnl::reorder::primitive_desc(cpu_engine(), conv_->output_desc(), cpu_engine(), slice_));
    }
    // Only the output of a convolution into a slice is scratch (the tensor's part is copied from
    // it); a whole tensor's is the tensor itself.
  }

  void run(OpRun& pass) override {
    TensorStore& t = pass.tensors;
    const dnnl::memory in = t.memory(op_.in.tensor);
    std::optional<dnnl::memory> addend;
    if (op_.addend) addend = t.memory(op_.addend->tensor);
    if (whole_) conv_->set_output(t.data(op_.out.tensor));
    const dnnl::memory& out = conv_->run(pass.stream, in, addend ? &*addend : nullptr);
    if (!whole_) {
      dnnl::memory src = out;
      dnnl::memory dst(slice_, cpu_engine(), t.data(op_.out.tensor));
      to_slice_->execute(pass.stream, src, dst);
    }
    pass.stream.wait();
  }

 private:
  const graph::Conv2d<HostTensor> op_;
  bool whole_ = true;
  std::optional<ConvOp> conv_;
  dnnl::memory::desc slice_;
  std::optional<dnnl::reorder> to_slice_;
};

}  // namespace

std::unique_ptr<CpuOp> build_op(const graph::Conv2d<HostTensor>& op, OpBuild& b) {
  if (b.fused_mask == &op) return nullptr;  // computed by the convex upsampling that reads it
  return std::make_unique<Conv2dOp>(op, b);
}

}  // namespace neuflow::model
