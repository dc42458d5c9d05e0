// Which concatenations the Vulkan backend reads in place (vulkan/inputs_in_parts.hpp): the
// convolutions that read one then read its parts, and the concatenation is never written, so
// each refusal below is a case where that would give a wrong flow. Graph logic alone: no device.
#include <gtest/gtest.h>

#include <cstddef>
#include <vector>

#include "vulkan/inputs_in_parts.hpp"

namespace neuflow::model::vulkan {
namespace {

using Ops = graph::OpList<DeviceTensor>;

// A 64×64 concatenation of a 1/1 tensor and a 1/2 one upsampled, read by one 3×3 convolution:
// large enough that the convolution runs by Winograd (takes_winograd).
struct Concatenation {
  graph::TensorTable t;
  graph::TensorId a, s, x, y;
  BasicConvWeights<DeviceTensor> w{8, 16, 3, 3, {0}, {-1}};
  Concatenation() {
    a = t.add({"a", 8, 64, 64});
    s = t.add({"s", 8, 32, 32});
    x = t.add({"x", 16, 64, 64});
    y = t.add({"y", 8, 64, 64});
  }
  graph::Node<DeviceTensor> conv(int id) const {
    return {id, graph::Conv2d<DeviceTensor>{&w, "conv", t.all(x), t.all(y), 1, 1}};
  }
  // The sources written, the two parts, the convolution: ops 0 .. 4.
  Ops ops() const {
    return {{0, graph::Zero{t.all(a)}},
            {1, graph::Zero{t.all(s)}},
            {2, graph::Copy{t.all(a), t.all(x).channels(0, 8)}},
            {3, graph::Resample{t.all(s), t.all(x).channels(8, 8), 2, true, 1.f}},
            conv(4)};
  }
  bool found(const Ops& ops, ConvAlgorithm conv = ConvAlgorithm::winograd_fused) const {
    return input_in_parts_at(ops, t, 2, conv).has_value();
  }
};

TEST(InputsInParts, OneDispatchWinogradConvolutionsReadAConcatenationsParts) {
  const Concatenation c;
  const auto found = input_in_parts_at(c.ops(), c.t, 2, ConvAlgorithm::winograd_fused);
  ASSERT_TRUE(found.has_value());
  EXPECT_EQ(found->writers, (std::vector<std::size_t>{2, 3}));
  EXPECT_EQ(found->readers, (std::vector<std::size_t>{4}));
  EXPECT_EQ(found->parts.first.in.tensor, c.a);
  EXPECT_EQ(found->parts.first.factor, 1);
  ASSERT_TRUE(found->parts.second.has_value());
  EXPECT_EQ(found->parts.second->in.tensor, c.s);
  EXPECT_EQ(found->parts.second->factor, 2);
  EXPECT_TRUE(found->parts.second->relu);
  // Every reader up to the next whole write of x; a second one after it is another story.
  Ops two = c.ops();
  two.push_back(c.conv(5));
  two.push_back({6, graph::Zero{c.t.all(c.x)}});
  two.push_back(c.conv(7));
  EXPECT_EQ(input_in_parts_at(two, c.t, 2, ConvAlgorithm::winograd_fused)->readers, (std::vector<std::size_t>{4, 5}));
}

TEST(InputsInParts, TheMemoryPlanKeepsEachPartsSourceUntilItsLastReader) {
  const Concatenation c;
  const Ops ops = c.ops();
  const graph::LiveRanges plain = graph::live_ranges<DeviceTensor>(c.t, {&ops});
  const graph::LiveRanges planned = planned_live_ranges(c.t, {}, ops, ConvAlgorithm::winograd_fused);
  ASSERT_EQ(plain[static_cast<std::size_t>(c.s)].size(), 1u);
  EXPECT_EQ(plain[static_cast<std::size_t>(c.a)][0].last, 2);
  EXPECT_EQ(plain[static_cast<std::size_t>(c.s)][0].last, 3);
  EXPECT_EQ(planned[static_cast<std::size_t>(c.a)][0].last, 4);
  EXPECT_EQ(planned[static_cast<std::size_t>(c.s)][0].last, 4);
  const graph::LiveRanges direct = planned_live_ranges(c.t, {}, ops, ConvAlgorithm::direct);
  EXPECT_EQ(direct[static_cast<std::size_t>(c.s)][0].last, 3);
}

TEST(InputsInParts, AConcatenationAnythingElseNeedsIsWritten) {
  const Concatenation c;
  ASSERT_TRUE(c.found(c.ops()));
  // The convolution by another algorithm, which reads the tensor as it is.
  EXPECT_FALSE(c.found(c.ops(), ConvAlgorithm::direct));
  EXPECT_FALSE(c.found(c.ops(), ConvAlgorithm::winograd_split));
  // An observer reads the concatenation.
  Ops observed = c.ops();
  observed.insert(observed.begin() + 4, {5, graph::StageEnd{"stage", {{"x", 0, c.t.all(c.x)}}}});
  EXPECT_FALSE(c.found(observed));
  // A source written again before the convolution reads it.
  Ops rewritten = c.ops();
  rewritten.insert(rewritten.begin() + 4, {5, graph::Zero{c.t.all(c.s)}});
  EXPECT_FALSE(c.found(rewritten));
  Ops first_rewritten = c.ops();
  first_rewritten.insert(first_rewritten.begin() + 3, {5, graph::Zero{c.t.all(c.a)}});
  EXPECT_FALSE(c.found(first_rewritten));
  // Some of its channels written again, then read.
  Ops partly = c.ops();
  partly.push_back({5, graph::Zero{c.t.all(c.x).channels(0, 4)}});
  partly.push_back(c.conv(6));
  EXPECT_FALSE(c.found(partly));
  // A reader of some of its channels.
  Ops slice = c.ops();
  slice.push_back({5, graph::Copy{c.t.all(c.x).channels(8, 8), c.t.all(c.y)}});
  EXPECT_FALSE(c.found(slice));
  // The parts not in channel order, or not all of the tensor.
  Ops swapped = c.ops();
  std::get<graph::Copy>(swapped[2].op).out = c.t.all(c.x).channels(8, 8);
  EXPECT_FALSE(c.found(swapped));
  Ops one_part = c.ops();
  one_part.erase(one_part.begin() + 3);
  EXPECT_FALSE(c.found(one_part));
  // A factor that is not a power of two.
  Ops odd = c.ops();
  std::get<graph::Resample>(odd[3].op).factor = 3;
  EXPECT_FALSE(c.found(odd));
  // A convolution too small to run by Winograd (8×8 output).
  Concatenation small;
  small.t = graph::TensorTable{};
  small.a = small.t.add({"a", 8, 8, 8});
  small.s = small.t.add({"s", 8, 4, 4});
  small.x = small.t.add({"x", 16, 8, 8});
  small.y = small.t.add({"y", 8, 8, 8});
  EXPECT_FALSE(small.found(small.ops()));
}

}  // namespace
}  // namespace neuflow::model::vulkan
