#include "graph/memory_plan.hpp"

#include <algorithm>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>

namespace neuflow::model::graph {

namespace {

bool planned(const TensorDesc& d) { return d.storage == Storage::transient; }

bool meet(const std::vector<LiveRange>& a, const std::vector<LiveRange>& b) { return live_at_once(a, b); }

// Whether a's and b's ranges meet or come within `apart` ops of each other.
bool near(const std::vector<LiveRange>& a, const std::vector<LiveRange>& b, int apart) {
  for (const LiveRange& x : a) {
    for (const LiveRange& y : b) {
      if (x.first <= y.last + apart && y.first <= x.last + apart) return true;
    }
  }
  return false;
}

}  // namespace

bool live_at_once(const std::vector<LiveRange>& a, const std::vector<LiveRange>& b) { return near(a, b, 0); }

void stretch_live_range(LiveRanges& ranges, TensorId tensor, int read_at, int last) {
  for (LiveRange& r : ranges[static_cast<std::size_t>(tensor)]) {
    if (r.first <= read_at && read_at <= r.last) r.last = std::max(r.last, last);
  }
}

OffsetPlan plan_offsets(const std::vector<std::size_t>& bytes, const LiveRanges& ranges, std::size_t alignment) {
  OffsetPlan plan;
  plan.offset.assign(bytes.size(), 0);
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    if (!ranges[i].empty() && bytes[i] > 0) order.push_back(i);
  }
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return bytes[a] > bytes[b]; });
  const auto align = [&](std::size_t n) { return (n + alignment - 1) / alignment * alignment; };
  std::vector<std::size_t> placed;
  for (const std::size_t i : order) {
    // The blocks already placed that are live with this one, by offset: the first gap that fits.
    std::vector<std::pair<std::size_t, std::size_t>> busy;
    for (const std::size_t p : placed) {
      if (live_at_once(ranges[i], ranges[p])) busy.emplace_back(plan.offset[p], plan.offset[p] + bytes[p]);
    }
    std::sort(busy.begin(), busy.end());
    std::size_t at = 0;
    for (const auto& [begin, end] : busy) {
      if (at + bytes[i] <= begin) break;
      at = std::max(at, align(end));
    }
    plan.offset[i] = at;
    plan.size = std::max(plan.size, at + bytes[i]);
    placed.push_back(i);
  }
  return plan;
}

template <typename T>
LiveRanges live_ranges(const TensorTable& tensors, const std::vector<const OpList<T>*>& passes) {
  LiveRanges ranges(tensors.size());
  std::vector<bool> open(tensors.size(), false);
  int index = 0;
  for (const OpList<T>* pass : passes) {
    std::fill(open.begin(), open.end(), false);
    for (const Node<T>& node : *pass) {
      // Reads first: an op that reads and writes a tensor continues its range.
      const Accesses a = accesses_of(node.op);
      for (const Slice& r : a.reads) {
        const auto i = static_cast<std::size_t>(r.tensor);
        if (!planned(tensors.at(r.tensor))) continue;
        if (!open[i]) {
          throw std::logic_error("the network graph reads " + tensors.at(r.tensor).name +
                                 " before any op of its pass writes it");
        }
        ranges[i].back().last = index;
      }
      for (const Slice& w : a.writes) {
        const auto i = static_cast<std::size_t>(w.tensor);
        if (!planned(tensors.at(w.tensor))) continue;
        const bool whole = !a.partial_rows && tensors.whole(w);
        const bool also_read =
            std::any_of(a.reads.begin(), a.reads.end(), [&](const Slice& r) { return r.tensor == w.tensor; });
        if (!open[i] || (whole && !also_read)) {
          ranges[i].push_back({index, index});
          open[i] = true;
        } else {
          ranges[i].back().last = index;
        }
      }
      ++index;
    }
  }
  return ranges;
}

template LiveRanges live_ranges(const TensorTable&, const std::vector<const OpList<std::vector<float>>*>&);
template LiveRanges live_ranges(const TensorTable&, const std::vector<const OpList<PackedTensor>*>&);

std::size_t MemoryPlan::planned_size() const {
  return std::accumulate(region_size.begin(), region_size.end(), std::size_t{0});
}

MemoryPlan plan_memory(const TensorTable& tensors, const LiveRanges& ranges, int apart) {
  MemoryPlan plan;
  plan.region.assign(tensors.size(), -1);
  std::vector<TensorId> order;
  for (std::size_t t = 0; t < tensors.size(); ++t) {
    if (!ranges[t].empty()) order.push_back(static_cast<TensorId>(t));
  }
  std::stable_sort(order.begin(), order.end(), [&](TensorId a, TensorId b) {
    return ranges[static_cast<std::size_t>(a)].front().first < ranges[static_cast<std::size_t>(b)].front().first;
  });
  std::vector<std::vector<TensorId>> members;
  for (const TensorId t : order) {
    const std::size_t need = tensors.at(t).count();
    int best = -1;
    // Growth first (what choosing the region adds to the total), then the tightest fit.
    std::size_t best_growth = std::numeric_limits<std::size_t>::max(), best_size = 0;
    for (std::size_t r = 0; r < members.size(); ++r) {
      const bool free = std::none_of(members[r].begin(), members[r].end(), [&](TensorId other) {
        return near(ranges[static_cast<std::size_t>(t)], ranges[static_cast<std::size_t>(other)], apart);
      });
      if (!free) continue;
      const std::size_t size = plan.region_size[r];
      const std::size_t growth = need > size ? need - size : 0;
      if (growth < best_growth || (growth == best_growth && size < best_size)) {
        best = static_cast<int>(r);
        best_growth = growth;
        best_size = size;
      }
    }
    // A new region costs `need`; growing one by as much or more is no better.
    if (best < 0 || best_growth >= need) {
      best = static_cast<int>(members.size());
      members.emplace_back();
      plan.region_size.push_back(0);
    }
    members[static_cast<std::size_t>(best)].push_back(t);
    plan.region_size[static_cast<std::size_t>(best)] = std::max(plan.region_size[static_cast<std::size_t>(best)], need);
    plan.region[static_cast<std::size_t>(t)] = best;
  }
  return plan;
}

void check_plan(const TensorTable& tensors, const MemoryPlan& plan, const LiveRanges& ranges) {
  for (std::size_t a = 0; a < tensors.size(); ++a) {
    if (ranges[a].empty()) continue;
    if (plan.region[a] < 0 ||
        tensors.at(static_cast<TensorId>(a)).count() > plan.region_size[static_cast<std::size_t>(plan.region[a])]) {
      throw std::logic_error("the memory plan has no room for " + tensors.at(static_cast<TensorId>(a)).name);
    }
    for (std::size_t b = a + 1; b < tensors.size(); ++b) {
      if (plan.region[a] == plan.region[b] && meet(ranges[a], ranges[b])) {
        throw std::logic_error("the memory plan puts " + tensors.at(static_cast<TensorId>(a)).name + " and " +
                               tensors.at(static_cast<TensorId>(b)).name + ", which are live at once, in one region");
      }
    }
  }
}

}  // namespace neuflow::model::graph
