#pragma once
// Each graph op on the CPU, one file per op (as vulkan/ops/ records them): built once per op id
// when the plan is made (primitives created, weights reordered), run on every pass.
#include <dnnl.hpp>

#include <memory>
#include <vector>

#include "dnnl/plan_context.hpp"
#include "graph/ops.hpp"
#include "tensor.hpp"
#include "tensor_store.hpp"

namespace neuflow::model {

using HostTensor = std::vector<float>;

// What a pass gives its ops.
struct OpRun {
  TensorStore& tensors;
  dnnl::stream& stream;
  const Tensor* image = nullptr;  // an encode pass's frame, [height, width, 3]
};

class CpuOp {
 public:
  virtual ~CpuOp() = default;
  virtual void run(OpRun& pass) = 0;
};

// What building an op needs: the tensors (whose layouts it may choose), the arena for what it
// uses only while it runs (every op's such memory overlaps every other's), and the plan's
// choices for it.
struct OpBuild {
  TensorStore& tensors;
  PlanContext& scratch;
  bool repeated = false;  // it runs several times a pair (a refinement step)
  // ConvexUpsample: the 1×1 convolution whose mask it computes itself, band by band.
  const graph::Conv2d<HostTensor>* fused_mask = nullptr;
};

std::unique_ptr<CpuOp> build_op(const graph::FrameInput& op, OpBuild& b);
std::unique_ptr<CpuOp> build_op(const graph::AvgPool2x& op, OpBuild& b);
std::unique_ptr<CpuOp> build_op(const graph::Conv2d<HostTensor>& op, OpBuild& b);
std::unique_ptr<CpuOp> build_op(const graph::Linear<HostTensor>& op, OpBuild& b);
std::unique_ptr<CpuOp> build_op(const graph::Attention& op, OpBuild& b);
std::unique_ptr<CpuOp> build_op(const graph::LayerNorm<HostTensor>& op, OpBuild& b);
std::unique_ptr<CpuOp> build_op(const graph::ChannelAffine<HostTensor>& op, OpBuild& b);
std::unique_ptr<CpuOp> build_op(const graph::GlobalMatching& op, OpBuild& b);
std::unique_ptr<CpuOp> build_op(const graph::Resample& op, OpBuild& b);
std::unique_ptr<CpuOp> build_op(const graph::Copy& op, OpBuild& b);
std::unique_ptr<CpuOp> build_op(const graph::CopyRows& op, OpBuild& b);
std::unique_ptr<CpuOp> build_op(const graph::Zero& op, OpBuild& b);
std::unique_ptr<CpuOp> build_op(const graph::LocalCorrelation& op, OpBuild& b);
std::unique_ptr<CpuOp> build_op(const graph::RefineUpdate& op, OpBuild& b);
std::unique_ptr<CpuOp> build_op(const graph::ConvexUpsample& op, OpBuild& b);
std::unique_ptr<CpuOp> build_op(const graph::Output& op, OpBuild& b);
std::unique_ptr<CpuOp> build_op(const graph::StageEnd& op, OpBuild& b);

// An op whose run() is a function of the pass alone.
template <typename F>
class LambdaOp final : public CpuOp {
 public:
  explicit LambdaOp(F f) : f_(std::move(f)) {}
  void run(OpRun& pass) override { f_(pass); }

 private:
  F f_;
};
template <typename F>
std::unique_ptr<CpuOp> make_op(F f) {
  return std::make_unique<LambdaOp<F>>(std::move(f));
}

}  // namespace neuflow::model
