#pragma once
// Memory from the graph: each transient tensor's live ranges over the ops of a backend's passes,
// and regions shared by tensors whose ranges never meet. A backend allocates one buffer per
// region (never one for all of them: a GPU's largest buffer is often 128 MiB or so) and gives
// persistent and frame tensors memory of their own.
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

#include "graph/ops.hpp"
#include "graph/tensors.hpp"

namespace neuflow::model::graph {

// Op indices, both inclusive, counted over all passes in the order given.
struct LiveRange {
  int first = 0, last = 0;
};
using LiveRanges = std::vector<std::vector<LiveRange>>;  // per tensor; none for unplanned ones

// A tensor is live from an op that writes it to the last op that reads it; an op that writes all
// of it without reading it starts a new range (a refinement step's temporaries live within the
// step). Each pass may run alone, so no transient tensor lives from one pass into the next:
// std::logic_error naming the tensor when an op reads one that its pass has not written.
template <typename T>
LiveRanges live_ranges(const TensorTable& tensors, const std::vector<const OpList<T>*>& passes);

struct MemoryPlan {
  std::vector<int> region;               // per tensor: its region; -1 for tensors not planned
  std::vector<std::size_t> region_size;  // per region: elements, its largest tensor's
  std::size_t planned_size() const;      // the regions' elements together
};

// Greedy: tensors in the order they are first written, each into the smallest region whose
// tensors' ranges it does not meet and that needs the least growth. `apart`: a region's tensors'
// ranges are also at least that many ops apart, so that ops that close to each other never
// write what the other reads in one buffer (a GPU runs them without a barrier between them).
MemoryPlan plan_memory(const TensorTable& tensors, const LiveRanges& ranges, int apart = 0);

// Offsets in one allocation (a CPU's): each block of bytes at the lowest offset, aligned, free
// throughout its ranges; the largest blocks placed first, which leaves less unused between them
// than placing them as they come. Blocks without ranges get no place (offset 0, never used).
struct OffsetPlan {
  std::vector<std::size_t> offset;  // per block
  std::size_t size = 0;             // bytes the allocation needs
};
OffsetPlan plan_offsets(const std::vector<std::size_t>& bytes, const LiveRanges& ranges, std::size_t alignment);

// std::logic_error when two blocks that overlap in the allocation are live at once under
// `ranges`; `name(i)` names block i.
template <typename Name>
void check_offsets(const OffsetPlan& plan, const std::vector<std::size_t>& bytes, const LiveRanges& ranges,
                   const Name& name);

// `tensor`'s range that holds op `read_at` made to last until op `last` at least: for a backend
// that reads the tensor later than the graph's order says (a fused dispatch).
void stretch_live_range(LiveRanges& ranges, TensorId tensor, int read_at, int last);

// Whether two tensors' ranges meet.
bool live_at_once(const std::vector<LiveRange>& a, const std::vector<LiveRange>& b);

// std::logic_error naming both tensors when two tensors of one region are live at once under
// `ranges` (the ranges of other passes than the plan was made for, e.g. other iterations).
void check_plan(const TensorTable& tensors, const MemoryPlan& plan, const LiveRanges& ranges);

template <typename Name>
void check_offsets(const OffsetPlan& plan, const std::vector<std::size_t>& bytes, const LiveRanges& ranges,
                   const Name& name) {
  for (std::size_t a = 0; a < bytes.size(); ++a) {
    if (ranges[a].empty()) continue;
    for (std::size_t b = a + 1; b < bytes.size(); ++b) {
      if (ranges[b].empty()) continue;
      const bool overlap = plan.offset[a] < plan.offset[b] + bytes[b] && plan.offset[b] < plan.offset[a] + bytes[a];
      if (overlap && live_at_once(ranges[a], ranges[b])) {
        throw std::logic_error("the memory plan overlaps " + name(a) + " and " + name(b) + ", which are live at once");
      }
    }
  }
}

}  // namespace neuflow::model::graph
