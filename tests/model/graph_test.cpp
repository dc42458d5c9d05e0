// The network graph both backends run: its ops fit their tensors and the architecture table, its
// tensors and op ids do not depend on the iterations, and the memory planned from its live
// ranges never gives two tensors that are alive at once the same bytes.
#include <gtest/gtest.h>
#include <array>

#include <cstdio>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "checkpoint_builder.hpp"
#include "graph/memory_plan.hpp"
#include "graph/network_graph.hpp"
#include "neuflow/model/checkpoint.hpp"
#include "neuflow/model/stage_observer.hpp"
#include "support/temp_dir.hpp"
#include "weights.hpp"

namespace neuflow::test {
namespace {

namespace graph = model::graph;
using Host = std::vector<float>;

const model::NetworkWeights& weights() {
  static const model::NetworkWeights w = [] {
    TempDir dir;
    fake_neuflow_checkpoint().write(dir / "n.pth");
    return model::build_network_weights(model::load_checkpoint(dir / "n.pth"));
  }();
  return w;
}

// As a GPU holds them: each tensor an offset into one buffer.
model::BasicNetworkWeights<model::PackedTensor> packed() {
  int next = 0;
  auto pack = [&](const Host& values) {
    const model::PackedTensor t{values.empty() ? -1 : next};
    next += static_cast<int>(values.size());
    return t;
  };
  model::BasicNetworkWeights<model::PackedTensor> out;
  model::map_weights(weights(), pack, out);
  return out;
}

graph::NetworkGraph<Host> build(model::Iterations iterations, int height = 96, int width = 160, int rows = 7) {
  return graph::build_network_graph<Host>(weights(), height, width, iterations, rows);
}

std::vector<std::string> observed_names(const graph::OpList<Host>& ops) {
  std::vector<std::string> names;
  for (const auto& node : ops) {
    if (const auto* s = std::get_if<graph::StageEnd>(&node.op)) {
      for (const auto& o : s->observed) names.push_back(o.name + "/" + std::to_string(o.frame));
    }
  }
  return names;
}

TEST(NetworkGraph, EveryOpFitsItsTensorsAndTheArchitectureTable) {
  EXPECT_NO_THROW(graph::check_shapes(build({1, 8})));
  const auto gpu_weights = packed();
  EXPECT_NO_THROW(graph::check_shapes(graph::build_network_graph(gpu_weights, 64, 64, {2, 3}, 16)));
}

TEST(NetworkGraph, TheFlowPassShowsTheObserverEveryStageInTheReferencesOrder) {
  namespace s = model::stage;
  const std::vector<std::string> names = observed_names(build({1, 2}).flow);
  const auto it = [](std::string_view scale, int i) {
    return std::vector<std::string>{s::corr_iteration(scale, i) + "/0", s::refine_iteration(scale, i) + "_hidden/0",
                                    s::refine_iteration(scale, i) + "_delta/0"};
  };
  std::vector<std::string> expected{"backbone_s16/0", "backbone_s16/1",   "backbone_s8/0",    "backbone_s8/1",
                                    "conv_s8/0",      "cross_attn_s16/0", "cross_attn_s16/1", "global_matching_flow/0"};
  for (const auto& n : it(s::scale_s16, 0)) expected.push_back(n);
  for (const char* n : {"merge_s8/0", "merge_s8/1", "context_merge_s8/0"}) expected.emplace_back(n);
  for (int i = 0; i < 2; ++i) {
    for (const auto& n : it(s::scale_s8, i)) expected.push_back(n);
  }
  expected.emplace_back("flow/0");
  EXPECT_EQ(names, expected);
}

TEST(NetworkGraph, TensorsAndOpIdsDoNotDependOnTheIterations) {
  const auto planned = build({1, 8});
  for (const model::Iterations it : {model::Iterations{0, 0}, {1, 1}, {3, 2}, {32, 64}}) {
    SCOPED_TRACE(std::to_string(it.s16) + "," + std::to_string(it.s8));
    const auto g = build(it);
    ASSERT_EQ(g.tensors.size(), planned.tensors.size());
    EXPECT_EQ(g.op_ids, planned.op_ids);
    for (std::size_t t = 0; t < g.tensors.size(); ++t) {
      EXPECT_EQ(g.tensors.descs()[t].name, planned.tensors.descs()[t].name);
    }
    // A step's ops repeat with their ids: as many refinement convolutions as iterations, one id each.
    std::size_t refinement_steps = 0;
    std::set<int> ids;
    for (const auto& node : g.flow) {
      EXPECT_LT(node.id, g.op_ids);
      if (std::holds_alternative<graph::RefineUpdate>(node.op)) {
        ++refinement_steps;
        ids.insert(node.id);
      }
    }
    EXPECT_EQ(refinement_steps, static_cast<std::size_t>(it.s16 + it.s8));
    EXPECT_EQ(ids.size(), static_cast<std::size_t>((it.s16 > 0) + (it.s8 > 0)));
  }
}

TEST(NetworkGraph, AnOpThatDoesNotFitIsNamed) {
  auto g = build({1, 1});
  for (auto& node : g.flow) {
    if (auto* conv = std::get_if<graph::Conv2d<Host>>(&node.op); conv && conv->layer == "merge_s8.2") {
      conv->out.c -= 1;
      break;
    }
  }
  try {
    graph::check_shapes(g);
    FAIL() << "a convolution writing one channel too few passed";
  } catch (const std::logic_error& e) {
    EXPECT_NE(std::string(e.what()).find("conv2d merge_s8.2"), std::string::npos) << e.what();
  }
}

TEST(MemoryPlan, RegionsHoldOnlyTensorsNeverAliveAtOnceAtAnyIterations) {
  const auto planned = build({2, 2}, 1088, 1920, 1028);  // as the Vulkan backend plans full HD
  const auto ranges = graph::live_ranges<Host>(planned.tensors, {&planned.encode, &planned.flow});
  const graph::MemoryPlan plan = graph::plan_memory(planned.tensors, ranges);
  EXPECT_NO_THROW(graph::check_plan(planned.tensors, plan, ranges));
  for (const model::Iterations it : {model::Iterations{0, 0}, {1, 1}, {1, 8}, {5, 12}}) {
    const auto g = build(it, 1088, 1920, 1028);
    EXPECT_NO_THROW(graph::check_plan(g.tensors, plan, graph::live_ranges<Host>(g.tensors, {&g.encode, &g.flow})))
        << it.s16 << "," << it.s8;
  }
  std::size_t separate = 0;
  for (std::size_t t = 0; t < planned.tensors.size(); ++t) {
    if (!ranges[t].empty()) separate += planned.tensors.descs()[t].count();
  }
  // The figure the plan is for: every transient tensor in memory of its own would take this much.
  std::printf("planned %zu regions, %.1f M values; one buffer per tensor: %.1f M values\n", plan.region_size.size(),
              static_cast<double>(plan.planned_size()) / 1e6, static_cast<double>(separate) / 1e6);
  EXPECT_LT(plan.planned_size(), separate / 2);
  // As the Vulkan backend plans it: no region shared by tensors within three ops of each other
  // (two, as it once did, to compare).
  for (const int ops : {2, 3}) {
    const graph::MemoryPlan apart = graph::plan_memory(planned.tensors, ranges, ops);
    EXPECT_NO_THROW(graph::check_plan(planned.tensors, apart, ranges));
    std::printf("%d ops apart: %zu regions, %.1f M values\n", ops, apart.region_size.size(),
                static_cast<double>(apart.planned_size()) / 1e6);
    EXPECT_LT(apart.planned_size(), separate / 2);
  }
}

// a → b and c → d side by side: packed tightly, c could take a's region and be written right
// after a is last read, which a GPU must order with a barrier. Two ops apart, it cannot.
TEST(MemoryPlan, TensorsOpsApartNeverShareARegion) {
  graph::TensorTable tensors;
  std::array<graph::TensorId, 4> ids{};
  for (std::size_t i = 0; i < ids.size(); ++i) {
    ids[i] = tensors.add({std::string(1, static_cast<char>('a' + i)), 2, 4, 4});
  }
  const auto [a, b, c, d] = ids;
  graph::OpList<Host> pass{{0, graph::Zero{tensors.all(a)}},   {1, graph::Copy{tensors.all(a), tensors.all(b)}},
                           {2, graph::Zero{tensors.all(c)}},   {3, graph::Copy{tensors.all(c), tensors.all(d)}},
                           {4, graph::Output{tensors.all(b)}}, {5, graph::Output{tensors.all(d)}}};
  const auto ranges = graph::live_ranges<Host>(tensors, {&pass});
  const auto region = [](const graph::MemoryPlan& plan, graph::TensorId t) {
    return plan.region[static_cast<std::size_t>(t)];
  };
  const graph::MemoryPlan tight = graph::plan_memory(tensors, ranges);
  EXPECT_EQ(region(tight, c), region(tight, a)) << "a is dead once op 1 has read it";
  const graph::MemoryPlan apart = graph::plan_memory(tensors, ranges, 2);
  EXPECT_NE(region(apart, c), region(apart, a));
  EXPECT_NO_THROW(graph::check_plan(tensors, apart, ranges));
}

TEST(MemoryPlan, AStepsTemporariesLiveWithinTheStep) {
  const auto g = build({1, 3});
  const auto ranges = graph::live_ranges<Host>(g.tensors, {&g.encode, &g.flow});
  for (std::size_t t = 0; t < g.tensors.size(); ++t) {
    const std::string& name = g.tensors.descs()[t].name;
    if (name == "refine_s8.conv2") {
      EXPECT_EQ(ranges[t].size(), 3u) << "one range a step";
    }
    if (name == "refine_s8.input") {
      EXPECT_EQ(ranges[t].size(), 1u) << "the step's input carries the hidden state";
    }
    if (g.tensors.descs()[t].storage != graph::Storage::transient) {
      EXPECT_TRUE(ranges[t].empty()) << name;
    }
  }
}

// Two frames' rows copied into one tensor: the second copy, whole in channels but not in rows,
// continues the range the first began, so nothing planned between them can take its memory.
TEST(MemoryPlan, ARowCopyContinuesItsTensorsRange) {
  graph::TensorTable tensors;
  const auto frame0 = tensors.add({"frame0", 2, 4, 4});
  const auto frame1 = tensors.add({"frame1", 2, 4, 4});
  const auto both = tensors.add({"both", 2, 8, 4});
  const auto other = tensors.add({"other", 2, 4, 4});
  graph::OpList<Host> pass{{0, graph::Zero{tensors.all(frame0)}},
                           {1, graph::Zero{tensors.all(frame1)}},
                           {2, graph::CopyRows{tensors.all(frame0), tensors.all(both), 0, 0, 4}},
                           {3, graph::Zero{tensors.all(other)}},
                           {4, graph::CopyRows{tensors.all(frame1), tensors.all(both), 0, 4, 4}},
                           {5, graph::Copy{tensors.all(other), tensors.all(frame0)}},
                           {6, graph::Output{tensors.all(both).channels(0, 2)}}};
  const auto ranges = graph::live_ranges<Host>(tensors, {&pass});
  ASSERT_EQ(ranges[static_cast<std::size_t>(both)].size(), 1u);
  EXPECT_EQ(ranges[static_cast<std::size_t>(both)][0].first, 2);
  EXPECT_EQ(ranges[static_cast<std::size_t>(both)][0].last, 6);
}

TEST(MemoryPlan, ATensorReadBeforeItsPassWritesItIsAnError) {
  graph::TensorTable tensors;
  const auto a = tensors.add({"a", 2, 4, 4});
  const auto b = tensors.add({"b", 2, 4, 4});
  graph::OpList<Host> pass{{0, graph::Copy{tensors.all(a), tensors.all(b)}}};
  try {
    graph::live_ranges<Host>(tensors, {&pass});
    FAIL() << "reading a tensor nothing wrote passed";
  } catch (const std::logic_error& e) {
    EXPECT_NE(std::string(e.what()).find("reads a before"), std::string::npos) << e.what();
  }
}

TEST(MemoryPlan, OffsetsNeverOverlapBlocksAliveAtOnce) {
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> size(1, 5000), start(0, 60), length(0, 12);
  std::vector<std::size_t> bytes;
  graph::LiveRanges ranges;
  for (int i = 0; i < 200; ++i) {
    bytes.push_back(static_cast<std::size_t>(size(rng)));
    const int first = start(rng);
    ranges.push_back({{first, first + length(rng)}, {first + 20, first + 20 + length(rng)}});
  }
  const auto plan = graph::plan_offsets(bytes, ranges, 64);
  const auto name = [](std::size_t i) { return std::to_string(i); };
  EXPECT_NO_THROW(graph::check_offsets(plan, bytes, ranges, name));
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    EXPECT_EQ(plan.offset[i] % 64, 0u);
    EXPECT_LE(plan.offset[i] + bytes[i], plan.size);
  }
  // Two blocks alive together moved onto one another: the check names them.
  auto broken = plan;
  std::size_t a = 0, b = 1;
  while (!graph::live_at_once(ranges[a], ranges[b])) ++b;
  broken.offset[b] = broken.offset[a];
  EXPECT_THROW(graph::check_offsets(broken, bytes, ranges, name), std::logic_error);
}

}  // namespace
}  // namespace neuflow::test
