#include "network.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "kernels/feature_ops.hpp"

namespace neuflow::model {

namespace {

// Query rows per attention and matching block: the score block at most 1M floats (4 MB).
constexpr int kScoreBlockFloats = 1 << 20;

int score_block_rows(int height, int width) {
  const int tokens = (height / 16) * (width / 16);
  return std::clamp(kScoreBlockFloats / std::max(tokens, 1), 1, tokens);
}

}  // namespace

NetworkPlan::NetworkPlan(const NetworkWeights& weights, int height, int width, CpuConvolution convolution)
    : height_(height),
      width_(width),
      weights_(weights),
      graph_(graph::build_network_graph<HostTensor>(weights, height, width, Iterations{},
                                                    score_block_rows(height, width))),
      tensors_(graph_.tensors) {
  graph::check_shapes(graph_);
  choose_layouts();
  // Ops that run several times a pair (the refinement steps) are built as repeated ones.
  std::vector<int> runs(static_cast<std::size_t>(graph_.op_ids), 0);
  for (const auto* pass : {&graph_.encode, &graph_.flow}) {
    for (const auto& node : *pass) ++runs[static_cast<std::size_t>(node.id)];
  }
  ops_.resize(static_cast<std::size_t>(graph_.op_ids));
  for (int i = 0; i < graph_.op_ids; ++i) scratch_.push_back({{}, convolution});
  std::vector<bool> built(ops_.size(), false);
  for (const auto* pass : {&graph_.encode, &graph_.flow}) {
    for (const auto& node : *pass) {
      const auto id = static_cast<std::size_t>(node.id);
      if (built[id]) continue;
      built[id] = true;
      OpBuild b{tensors_, scratch_[id], runs[id] > 1, fused_mask_};
      ops_[id] = std::visit([&](const auto& op) { return build_op(op, b); }, node.op);
      if (std::holds_alternative<graph::FrameInput>(node.op)) input_ = std::get<graph::FrameInput>(node.op).out.tensor;
    }
  }
  const std::vector<TensorStore::Block> blocks = scratch_blocks({&graph_.encode, &graph_.flow});
  const std::vector<std::byte*> at = tensors_.allocate(live_ranges({&graph_.encode, &graph_.flow}), blocks);
  for (std::size_t id = 0; id < scratch_.size(); ++id) scratch_[id].arena.bind(at[id]);
}

std::vector<TensorStore::Block> NetworkPlan::scratch_blocks(
    const std::vector<const graph::OpList<HostTensor>*>& passes) {
  std::vector<TensorStore::Block> blocks(scratch_.size());
  for (std::size_t id = 0; id < scratch_.size(); ++id) {
    blocks[id].name = "the scratch of op " + std::to_string(id);
    blocks[id].bytes = scratch_[id].arena.plan();
  }
  int index = 0;
  for (const auto* pass : passes) {
    for (const auto& node : *pass) {
      blocks[static_cast<std::size_t>(node.id)].ranges.push_back({index, index});
      ++index;
    }
  }
  return blocks;
}

graph::LiveRanges NetworkPlan::live_ranges(const std::vector<const graph::OpList<HostTensor>*>& passes) const {
  graph::LiveRanges ranges = graph::live_ranges<HostTensor>(graph_.tensors, passes);
  auto& input = ranges[static_cast<std::size_t>(fused_mask_->in.tensor)];
  int index = 0, mask_index = -1;
  for (const auto* pass : passes) {
    for (const auto& node : *pass) {
      if (node.id == fused_mask_id_) mask_index = index;
      if (std::holds_alternative<graph::ConvexUpsample>(node.op)) {
        for (graph::LiveRange& r : input) {
          if (r.first <= mask_index && mask_index <= r.last) r.last = std::max(r.last, index);
        }
      }
      ++index;
    }
  }
  return ranges;
}

NetworkPlan::Memory NetworkPlan::memory() const {
  Memory m{tensors_.allocated_bytes(), 0};
  for (const PlanContext& s : scratch_) m.largest_scratch = std::max(m.largest_scratch, s.arena.size_bytes());
  return m;
}

// A tensor stays in its convolution's layout when convolutions alone write it (whole) and read
// it; the convex upsampling computes its mask itself from the 1×1 convolution that makes it.
void NetworkPlan::choose_layouts() {
  const std::size_t n = graph_.tensors.size();
  std::vector<bool> conv_only(n, true), conv_written(n, false);
  std::vector<int> readers(n, 0);
  for (const auto* pass : {&graph_.encode, &graph_.flow}) {
    for (const auto& node : *pass) {
      const graph::Accesses a = graph::accesses_of(node.op);
      for (const graph::Slice& s : a.reads) ++readers[static_cast<std::size_t>(s.tensor)];
    }
  }
  for (const auto& node : graph_.flow) {
    const auto* up = std::get_if<graph::ConvexUpsample>(&node.op);
    if (!up) continue;
    for (const auto& writer : graph_.flow) {
      const auto* conv = std::get_if<graph::Conv2d<HostTensor>>(&writer.op);
      if (conv && conv->out.tensor == up->mask.tensor && readers[static_cast<std::size_t>(up->mask.tensor)] == 1) {
        fused_mask_ = conv;
        fused_mask_id_ = writer.id;
      }
    }
    if (!fused_mask_) throw std::logic_error("the CPU's convex upsampling needs its mask's convolution to itself");
    tensors_.exclude(up->mask.tensor);
  }
  for (const auto* pass : {&graph_.encode, &graph_.flow}) {
    for (const auto& node : *pass) {
      std::visit(
          [&](const auto& o) {
            using O = std::decay_t<decltype(o)>;
            if constexpr (std::is_same_v<O, graph::Conv2d<HostTensor>>) {
              if (&o != fused_mask_) {
                const auto out = static_cast<std::size_t>(o.out.tensor);
                if (o.out.channel == 0 && o.out.c == graph_.tensors.at(o.out.tensor).c) {
                  conv_written[out] = true;
                } else {
                  conv_only[out] = false;
                }
                return;
              }
            }
            const graph::Accesses a = o.accesses();
            for (const auto* slices : {&a.reads, &a.writes}) {
              for (const graph::Slice& s : *slices) conv_only[static_cast<std::size_t>(s.tensor)] = false;
            }
          },
          node.op);
    }
  }
  for (std::size_t t = 0; t < n; ++t) {
    const auto id = static_cast<graph::TensorId>(t);
    if (graph_.tensors.at(id).storage == graph::Storage::transient && conv_written[t] && conv_only[t]) {
      tensors_.keep_blocked(id);
    }
  }
}

void NetworkPlan::encode(dnnl::stream& stream, const Tensor& image, FrameFeatures& out) {
  tensors_.bind_frames({&out, nullptr, nullptr});
  OpRun pass{tensors_, stream, &image};
  run(graph_.encode, pass, nullptr);
}

const Tensor& NetworkPlan::flow(dnnl::stream& stream, const FrameFeatures& frame0, const FrameFeatures& frame1,
                                int iters_s16, int iters_s8, const StageObserver* observer) {
  // A flow pass only reads the frames' tensors.
  tensors_.bind_frames({nullptr, const_cast<FrameFeatures*>(&frame0), const_cast<FrameFeatures*>(&frame1)});
  OpRun pass{tensors_, stream};
  run(flow_ops({iters_s16, iters_s8}), pass, observer && *observer ? observer : nullptr);
  return tensors_.nhwc(graph_.output);
}

void NetworkPlan::run(const graph::OpList<HostTensor>& ops, OpRun& pass, const StageObserver* observer) {
  for (const auto& node : ops) {
    if (const auto* stage = std::get_if<graph::StageEnd>(&node.op)) {
      if (observer) observe(*stage, *observer);
    } else if (CpuOp* op = ops_[static_cast<std::size_t>(node.id)].get()) {
      op->run(pass);
    }
  }
}

void NetworkPlan::observe(const graph::StageEnd& stage, const StageObserver& observer) {
  for (const auto& o : stage.observed) {
    const Tensor& t = tensors_.nhwc(o.tensor.tensor);
    Tensor part;
    const bool whole = o.tensor.channel == 0 && o.tensor.c == t.c;
    if (!whole) part = extract_channels({&t, o.tensor.channel, o.tensor.c});
    const Tensor& seen = whole ? t : part;
    observer(StageTensor{o.name, o.frame, seen.h, seen.w, seen.c, seen.data.data()});
  }
}

const graph::OpList<HostTensor>& NetworkPlan::flow_ops(const Iterations& iterations) {
  if (iterations == Iterations{}) return graph_.flow;
  const std::pair key{iterations.s16, iterations.s8};
  if (auto it = flow_ops_.find(key); it != flow_ops_.end()) return it->second;
  auto g =
      graph::build_network_graph<HostTensor>(weights_, height_, width_, iterations, score_block_rows(height_, width_));
  if (g.tensors.size() != graph_.tensors.size() || g.op_ids != graph_.op_ids) {
    throw std::logic_error("the network graph's tensors or ops depend on its iterations");
  }
  tensors_.check(live_ranges({&g.encode, &g.flow}), scratch_blocks({&g.encode, &g.flow}));
  return flow_ops_.emplace(key, std::move(g.flow)).first->second;
}

}  // namespace neuflow::model
