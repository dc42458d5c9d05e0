#pragma once
// The network graph (graph/network_graph.hpp) on the CPU at one model resolution: each op built
// once (ops/: primitives created, weights reordered), every tensor in the TensorStore, a pass
// running the ops of the graph in order. The plan makes the CPU's own choices as attributes of
// the graph's tensors and ops: which tensors stay in a convolution's blocked layout, which
// convolutions use Winograd and which tile (repeated ones: the refinement steps), the mask
// convolution fused into the convex upsampling, and where each tensor lives in the one
// allocation its live ranges plan.
#include <dnnl.hpp>

#include <map>
#include <memory>
#include <utility>
#include <vector>

#include "dnnl/plan_context.hpp"
#include "graph/network_graph.hpp"
#include "neuflow/model/stage_observer.hpp"
#include "ops/cpu_op.hpp"
#include "tensor.hpp"
#include "tensor_store.hpp"
#include "weights.hpp"

namespace neuflow::model {

class NetworkPlan {
 public:
  // height, width: multiples of 16, at least 32. `convolution`: how the stride-1 3×3
  // convolutions are computed (any CpuConvolution; never read from the environment here).
  NetworkPlan(const NetworkWeights& weights, int height, int width, CpuConvolution convolution);
  NetworkPlan(const NetworkPlan&) = delete;
  NetworkPlan& operator=(const NetworkPlan&) = delete;

  int height() const { return height_; }
  int width() const { return width_; }

  // image: [height, width, 3] RGB in 0..1; input() or a tensor of the caller's.
  void encode(dnnl::stream& stream, const Tensor& image, FrameFeatures& out);
  // Where a frame may be converted before encode(): the graph's input tensor, in the plan's
  // memory, alive until encode() has read it.
  Tensor& input() { return tensors_.nhwc(input_); }

  // Flow from frame 0 to frame 1 at model resolution: [height, width, 2] (u, v) in pixels, in
  // the plan's memory: valid until the plan's next call.
  const Tensor& flow(dnnl::stream& stream, const FrameFeatures& frame0, const FrameFeatures& frame1, int iters_s16,
                     int iters_s8, const StageObserver* observer = nullptr);

  // Bytes: the one allocation (tensors and the ops' scratch), and the largest scratch of one
  // op (a Winograd workspace, a converted input, the output of a convolution into a slice).
  struct Memory {
    std::size_t allocation = 0, largest_scratch = 0;
  };
  Memory memory() const;

 private:
  void choose_layouts();
  void run(const graph::OpList<HostTensor>& ops, OpRun& pass, const StageObserver* observer);
  void observe(const graph::StageEnd& stage, const StageObserver& observer);
  const graph::OpList<HostTensor>& flow_ops(const Iterations& iterations);
  // The graph's live ranges, with the fused mask convolution's input alive until the convex
  // upsampling that reads it in its place.
  graph::LiveRanges live_ranges(const std::vector<const graph::OpList<HostTensor>*>& passes) const;
  // Each op's scratch as a block live wherever the passes run the op.
  std::vector<TensorStore::Block> scratch_blocks(const std::vector<const graph::OpList<HostTensor>*>& passes);

  int height_, width_;
  const NetworkWeights& weights_;
  graph::NetworkGraph<HostTensor> graph_;  // with the default iterations: what the plan is built for
  TensorStore tensors_;                    // of graph_'s tensors
  std::vector<PlanContext> scratch_;       // by op id: what the op uses only while it runs
  const graph::Conv2d<HostTensor>* fused_mask_ = nullptr;
  int fused_mask_id_ = -1;
  std::vector<std::unique_ptr<CpuOp>> ops_;  // by op id; none for ops without work of their own
  std::map<std::pair<int, int>, graph::OpList<HostTensor>> flow_ops_;  // other iterations, checked
  graph::TensorId input_ = -1;
};

}  // namespace neuflow::model
