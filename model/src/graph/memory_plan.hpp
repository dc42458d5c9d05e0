#pragma once
// Memory from the graph: each transient tensor's live ranges over the ops of a backend's passes,
// and regions shared by tensors whose ranges never meet. A backend allocates one buffer per
// region (never one for all of them: a GPU's largest buffer is often 128 MiB or so) and gives
// persistent and frame tensors memory of their own.
#include <cstddef>
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
// tensors' ranges it does not meet and that needs the least growth.
MemoryPlan plan_memory(const TensorTable& tensors, const LiveRanges& ranges);

// std::logic_error naming both tensors when two tensors of one region are live at once under
// `ranges` (the ranges of other passes than the plan was made for, e.g. other iterations).
void check_plan(const TensorTable& tensors, const MemoryPlan& plan, const LiveRanges& ranges);

}  // namespace neuflow::model::graph
