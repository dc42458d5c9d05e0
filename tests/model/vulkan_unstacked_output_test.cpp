// Which stacked outputs the Vulkan backend never writes (vulkan/unstacked_output.hpp): the
// LayerNorm then writes each frame's tokens where the copies that unstack them would, and those
// copies are not recorded, so each refusal below is a case where that would give a wrong flow.
// Graph logic alone: no device.
#include <gtest/gtest.h>

#include <array>
#include <cstddef>

#include "vulkan/inputs_in_parts.hpp"
#include "vulkan/unstacked_output.hpp"

namespace neuflow::model::vulkan {
namespace {

using Ops = graph::OpList<DeviceTensor>;

// Both frames' 8 channels of 4×6 tokens stacked in `both` (8 rows), LayerNorm'd, its BatchNorm
// folded in, then unstacked into f0 and f1 and read.
struct Stacked {
  graph::TensorTable t;
  graph::TensorId in, both, f0, f1;
  BasicLayerNormWeights<DeviceTensor> w{{0}, {8}};
  DeviceTensor scale{16}, shift{24};
  Stacked() {
    in = t.add({"in", 8, 8, 6});
    both = t.add({"both", 8, 8, 6});
    f0 = t.add({"f0", 8, 4, 6});
    f1 = t.add({"f1", 8, 4, 6});
  }
  graph::Node<DeviceTensor> unstack(int id, int frame, graph::TensorId to) const {
    return {id, graph::CopyRows{t.all(both), t.all(to), frame * 4, 0, 4}};
  }
  // ops 0 .. 6: the input, the LayerNorm (1), its BatchNorm, the copies (3, 4), their readers.
  Ops ops() const {
    return {{0, graph::Zero{t.all(in)}},
            {1, graph::LayerNorm<DeviceTensor>{&w, "norm", t.all(in), t.all(both), std::nullopt}},
            {2, graph::ChannelAffine<DeviceTensor>{&scale, &shift, "bn", t.all(both)}},
            unstack(3, 0, f0),
            unstack(4, 1, f1),
            {5, graph::Output{t.all(f0).channels(0, 2)}},
            {6, graph::Output{t.all(f1).channels(0, 2)}}};
  }
  bool found(const Ops& ops) const { return unstacked_output_at(ops, t, 1).has_value(); }
};

TEST(UnstackedOutput, TheLayerNormWritesEachFramesTokensWhereItsCopyWould) {
  const Stacked s;
  const auto found = unstacked_output_at(s.ops(), s.t, 1);
  ASSERT_TRUE(found.has_value());
  EXPECT_EQ(found->copies, (std::array<std::size_t, 2>{3, 4}));
  EXPECT_EQ(found->frames[0].tensor, s.f0);
  EXPECT_EQ(found->frames[1].tensor, s.f1);
  // The copies in either order; without the BatchNorm.
  Ops swapped = s.ops();
  swapped[3] = s.unstack(3, 1, s.f1);
  swapped[4] = s.unstack(4, 0, s.f0);
  const auto other = unstacked_output_at(swapped, s.t, 1);
  ASSERT_TRUE(other.has_value());
  EXPECT_EQ(other->copies, (std::array<std::size_t, 2>{4, 3}));
  EXPECT_EQ(other->frames[0].tensor, s.f0);
  Ops plain = s.ops();
  plain.erase(plain.begin() + 2);
  EXPECT_TRUE(unstacked_output_at(plain, s.t, 1).has_value());
}

TEST(UnstackedOutput, TheMemoryPlanHasEachFrameLiveFromTheLayerNorm) {
  const Stacked s;
  const Ops ops = s.ops();
  const graph::LiveRanges plain = graph::live_ranges<DeviceTensor>(s.t, {&ops});
  const graph::LiveRanges planned = planned_live_ranges(s.t, {}, ops, ConvAlgorithm::winograd_fused);
  EXPECT_EQ(plain[static_cast<std::size_t>(s.f0)][0].first, 3);
  EXPECT_EQ(plain[static_cast<std::size_t>(s.f1)][0].first, 4);
  EXPECT_EQ(planned[static_cast<std::size_t>(s.f0)][0].first, 1);
  EXPECT_EQ(planned[static_cast<std::size_t>(s.f1)][0].first, 1);
  EXPECT_EQ(planned[static_cast<std::size_t>(s.f1)][0].last, 6);
}

TEST(UnstackedOutput, AStackedTensorAnythingElseReadsIsWritten) {
  const Stacked s;
  ASSERT_TRUE(s.found(s.ops()));
  Ops read = s.ops();  // after the copies
  read.push_back({7, graph::Output{s.t.all(s.both).channels(0, 2)}});
  EXPECT_FALSE(s.found(read));
  Ops between = s.ops();  // between them
  between.insert(between.begin() + 4, {7, graph::Output{s.t.all(s.both).channels(0, 2)}});
  EXPECT_FALSE(s.found(between));
  Ops one = s.ops();  // only one frame copied out
  one.erase(one.begin() + 4);
  EXPECT_FALSE(s.found(one));
  Ops twice = s.ops();  // the same frame twice
  twice[4] = s.unstack(4, 0, s.f1);
  EXPECT_FALSE(s.found(twice));
}

TEST(UnstackedOutput, NotWhereTheFramesTensorsAreTouchedBeforeTheirCopies) {
  const Stacked s;
  Ops written = s.ops();  // f1 written between the LayerNorm and its copy
  written.insert(written.begin() + 3, {7, graph::Zero{s.t.all(s.f1)}});
  EXPECT_FALSE(s.found(written));
  Ops read = s.ops();  // f0 read there
  read.insert(read.begin() + 2, {7, graph::Output{s.t.all(s.f0).channels(0, 2)}});
  EXPECT_FALSE(s.found(read));
  Ops own = s.ops();  // the LayerNorm's residual is a frame's tensor
  std::get<graph::LayerNorm<DeviceTensor>>(own[1].op).residual = s.t.all(s.f0);
  EXPECT_FALSE(s.found(own));
}

TEST(UnstackedOutput, NotACopyOfOtherRowsChannelsOrShape) {
  const Stacked s;
  Ops rows = s.ops();  // rows 2 .. 5
  std::get<graph::CopyRows>(rows[3].op).in_row = 2;
  EXPECT_FALSE(s.found(rows));
  Ops channels = s.ops();  // some of the channels
  std::get<graph::CopyRows>(channels[3].op).in = s.t.all(s.both).channels(0, 4);
  EXPECT_FALSE(s.found(channels));
  Ops into = s.ops();  // into part of a tensor
  std::get<graph::CopyRows>(into[3].op).out = s.t.all(s.f0).channels(0, 4);
  EXPECT_FALSE(s.found(into));
  Ops same = s.ops();  // both into one tensor
  std::get<graph::CopyRows>(same[4].op).out = s.t.all(s.f0);
  EXPECT_FALSE(s.found(same));
  Ops partial = s.ops();  // a LayerNorm of some channels
  std::get<graph::LayerNorm<DeviceTensor>>(partial[1].op).out = s.t.all(s.both).channels(0, 4);
  EXPECT_FALSE(s.found(partial));
  Ops late = s.ops();  // the BatchNorm after a copy: the first copy would miss it
  std::swap(late[2], late[3]);
  EXPECT_FALSE(s.found(late));
}

}  // namespace
}  // namespace neuflow::model::vulkan
