#pragma once
// Where the CPU keeps the network graph's tensors. Each is NHWC (what token lists, correlation
// and the per-pixel ops want) unless only convolutions read it whole: then it stays in the
// layout its convolution chose (oneDNN's blocked one, or Winograd's), which is the attribute
// the executor decides per tensor. Transient tensors share one allocation, placed from their
// live ranges; persistent ones hold their constant channels; the frames' tensors are the
// session's (FrameFeatures), bound per pass.
#include <dnnl.hpp>

#include <array>
#include <cstddef>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "graph/memory_plan.hpp"
#include "graph/tensors.hpp"
#include "kernels/feature_ops.hpp"
#include "tensor.hpp"

namespace neuflow::model {

// One frame's encoded tensors, by the graph's names; kept by the session once per slot.
struct FrameFeatures {
  std::map<std::string, Tensor, std::less<>> tensors;
};

class TensorStore {
 public:
  explicit TensorStore(const graph::TensorTable& table);

  const graph::TensorDesc& desc(graph::TensorId id) const { return table_.at(id); }

  // Layout choices, made while the ops are built (before allocate()).
  void keep_blocked(graph::TensorId id) { entry(id).blocked = true; }
  bool blocked(graph::TensorId id) const { return entries_[index(id)].blocked; }
  // A blocked tensor's layout, set by the convolution that writes it.
  void set_layout(graph::TensorId id, const dnnl::memory::desc& layout) { entry(id).layout = layout; }
  // The tensor's layout: its convolution's, or NHWC.
  dnnl::memory::desc layout(graph::TensorId id) const;
  // A tensor no op materializes (its producer is fused into its reader).
  void exclude(graph::TensorId id) { entry(id).excluded = true; }

  // Memory that is not a tensor's but shares the allocation: an op's scratch, live while the
  // op runs.
  struct Block {
    std::string name;
    std::size_t bytes = 0;
    std::vector<graph::LiveRange> ranges;
  };
  // Places the transient tensors and the blocks in one allocation from their live ranges, gives
  // persistent tensors their memory and constant channels; the blocks' addresses.
  std::vector<std::byte*> allocate(const graph::LiveRanges& ranges, const std::vector<Block>& blocks);
  // std::logic_error when the placement does not hold for these ranges (another pass's).
  void check(const graph::LiveRanges& ranges, const std::vector<Block>& blocks) const;
  std::size_t allocated_bytes() const { return plan_.size; }

  // The frames a pass reads or writes, by graph::FrameRole; an encoded frame's tensors are
  // created (with their constant channels) the first time.
  void bind_frames(const std::array<FrameFeatures*, 3>& frames) { frames_ = frames; }

  // Run time: an NHWC tensor, a channel range of it, any tensor as oneDNN memory.
  Tensor& nhwc(graph::TensorId id);
  ChannelSlice slice(const graph::Slice& s) { return {&nhwc(s.tensor), s.channel, s.c}; }
  dnnl::memory memory(graph::TensorId id);
  void* data(graph::TensorId id);

 private:
  struct Entry {
    bool blocked = false, excluded = false;
    dnnl::memory::desc layout;
    dnnl::memory memory;  // a blocked tensor's, once allocated
    Tensor nhwc;          // an NHWC tensor's, a view once allocated
  };
  std::size_t index(graph::TensorId id) const { return static_cast<std::size_t>(id); }
  Entry& entry(graph::TensorId id) { return entries_.at(index(id)); }
  // Tensors first, then the blocks.
  std::vector<std::size_t> bytes(const std::vector<Block>& blocks) const;
  static graph::LiveRanges with(graph::LiveRanges ranges, const std::vector<Block>& blocks);

  const graph::TensorTable& table_;
  std::vector<Entry> entries_;
  std::array<FrameFeatures*, 3> frames_{};
  graph::OffsetPlan plan_;
  std::unique_ptr<std::byte[]> storage_;
};

// Writes `t`'s constant channels into an NHWC tensor of its shape.
void fill_constant_channels(const graph::TensorDesc& t, Tensor& out);

}  // namespace neuflow::model
