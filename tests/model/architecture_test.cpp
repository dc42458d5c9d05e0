// The NeuFlow-V2 state-dict table and the architecture check.
#include <gtest/gtest.h>

#include <set>

#include "checkpoint_builder.hpp"
#include "neuflow/model/architecture.hpp"
#include "neuflow/model/checkpoint.hpp"
#include "support/temp_dir.hpp"

namespace neuflow::test {
namespace {

using model::ParameterKind;

TEST(Architecture, TableHasTheCheckpointsParameterCount) {
  const auto& table = model::neuflow_v2_parameters();
  EXPECT_EQ(table.size(), 155u);
  int64_t parameters = 0;
  int64_t running = 0;
  int64_t counters = 0;
  std::set<std::string> names;
  for (const auto& spec : table) {
    EXPECT_TRUE(names.insert(spec.name).second) << "duplicate " << spec.name;
    EXPECT_EQ(model::classify_key(spec.name), spec.kind) << spec.name;
    switch (spec.kind) {
      case ParameterKind::kParameter: parameters += spec.numel(); break;
      case ParameterKind::kRunningStat: running += spec.numel(); break;
      case ParameterKind::kBatchCounter: counters += spec.numel(); break;
    }
  }
  EXPECT_EQ(parameters, model::kNeuflowV2ParameterCount);
  EXPECT_EQ(parameters, 9'029'536);
  EXPECT_EQ(running, 5'368);
  EXPECT_EQ(counters, 17);
}

TEST(Architecture, TableSpotChecks) {
  std::map<std::string, std::vector<int64_t>> shapes;
  for (const auto& spec : model::neuflow_v2_parameters()) shapes[spec.name] = spec.shape;
  using S = std::vector<int64_t>;
  EXPECT_EQ(shapes.at("backbone.block_8_1.conv1.weight"), (S{256, 3, 8, 8}));
  EXPECT_EQ(shapes.at("backbone.block_cat_16.conv2.weight"), (S{190, 190, 3, 3}));
  EXPECT_EQ(shapes.at("cross_attn_s16.layers.1.mlp.0.weight"), (S{384, 384}));
  EXPECT_EQ(shapes.at("cross_attn_s16.layers.1.mlp.2.weight"), (S{192, 384}));
  EXPECT_EQ(shapes.at("cross_attn_s16.norm.running_var"), (S{192}));
  EXPECT_EQ(shapes.at("merge_s8.3.num_batches_tracked"), (S{}));
  EXPECT_EQ(shapes.at("refine_s16.conv1.conv.weight"), (S{128, 212, 3, 3}));
  EXPECT_EQ(shapes.at("refine_s8.conv_layers.4.conv.weight"), (S{96, 96, 3, 3}));
  EXPECT_EQ(shapes.at("refine_s8.conv3.weight"), (S{66, 96, 3, 3}));
  EXPECT_EQ(shapes.at("conv_s8.conv1.weight"), (S{128, 3, 8, 8}));
  EXPECT_EQ(shapes.at("upsample_s8.conv1.weight"), (S{256, 130, 3, 3}));
  EXPECT_EQ(shapes.at("upsample_s8.conv3.weight"), (S{576, 512, 1, 1}));
}

TEST(Architecture, FakeNeuflowCheckpointMatches) {
  TempDir dir;
  fake_neuflow_checkpoint().write(dir / "n.pth");
  const auto ckpt = model::load_checkpoint(dir / "n.pth");
  EXPECT_EQ(model::find_architecture_mismatch(ckpt), std::nullopt);
  const auto count = model::count_parameters(ckpt);
  EXPECT_EQ(count.parameters, 9'029'536);
  EXPECT_EQ(count.buffers, 5'385);
  EXPECT_EQ(ckpt.at("refine_s8.conv3.bias").data[3], 0.003f);
  EXPECT_EQ(ckpt.at("conv_s8.norm2.num_batches_tracked").data[0], 42.f);
}

TEST(Architecture, MissingKeyIsNamed) {
  TempDir dir;
  auto fake = fake_neuflow_checkpoint();
  std::erase_if(fake.tensors, [](const FakeTensor& t) {
    return t.name == "refine_s8.conv_layers.2.conv.weight" || t.name == "upsample_s8.conv3.bias";
  });
  fake.write(dir / "n.pth");
  const auto mismatch = model::find_architecture_mismatch(model::load_checkpoint(dir / "n.pth"));
  ASSERT_TRUE(mismatch.has_value());
  EXPECT_EQ(*mismatch,
            "missing tensor 'refine_s8.conv_layers.2.conv.weight' [96, 96, 3, 3] (2 of "
            "NeuFlow-V2's 155 tensors are absent)");
}

TEST(Architecture, WrongShapeIsNamed) {
  TempDir dir;
  auto fake = fake_neuflow_checkpoint();
  for (auto& t : fake.tensors) {
    if (t.name == "cross_attn_s16.layers.0.k_proj.weight") t.size = {192, 191};
  }
  fake.write(dir / "n.pth");
  const auto mismatch = model::find_architecture_mismatch(model::load_checkpoint(dir / "n.pth"));
  ASSERT_TRUE(mismatch.has_value());
  EXPECT_EQ(*mismatch,
            "tensor 'cross_attn_s16.layers.0.k_proj.weight' has shape [192, 191] but NeuFlow-V2 "
            "expects [192, 192]");
}

TEST(Architecture, UnexpectedKeyIsNamed) {
  TempDir dir;
  auto fake = fake_neuflow_checkpoint();
  fake.tensors.push_back(
      {.name = "flow_attn_s16.q.weight", .storage_key = "0", .storage_numel = 1179648, .size = {4, 4}});
  fake.write(dir / "n.pth");
  const auto mismatch = model::find_architecture_mismatch(model::load_checkpoint(dir / "n.pth"));
  ASSERT_TRUE(mismatch.has_value());
  EXPECT_NE(mismatch->find("unexpected tensor 'flow_attn_s16.q.weight' [4, 4]"), std::string::npos) << *mismatch;
}

TEST(Architecture, BatchCountersAreOptionalAndModulePrefixIsStripped) {
  TempDir dir;
  auto fake = fake_neuflow_checkpoint();
  std::erase_if(fake.tensors, [](const FakeTensor& t) { return t.name.ends_with("num_batches_tracked"); });
  for (auto& t : fake.tensors) t.name = "module." + t.name;
  fake.wrapper = Wrapper::kStateDict;
  fake.write(dir / "n.pth");
  const auto ckpt = model::load_checkpoint(dir / "n.pth");
  EXPECT_TRUE(ckpt.stripped_module_prefix);
  EXPECT_EQ(ckpt.keys.size(), 138u);
  EXPECT_EQ(model::find_architecture_mismatch(ckpt), std::nullopt);
  EXPECT_EQ(model::count_parameters(ckpt).parameters, 9'029'536);
}

TEST(Architecture, HalfPrecisionCheckpointMatches) {
  // A model.half() save: float16 storages, the counters still int64.
  TempDir dir;
  auto fake = fake_neuflow_checkpoint();
  int64_t largest = 0;
  for (auto& t : fake.tensors) {
    if (t.storage_type == "FloatStorage") {
      t.storage_type = "HalfStorage";
      largest = t.storage_numel;
    }
  }
  fake.storages[0].second = le_u16(std::vector<uint16_t>(static_cast<std::size_t>(largest), 0x3c00));
  fake.write(dir / "h.pth");
  const auto ckpt = model::load_checkpoint(dir / "h.pth");
  EXPECT_EQ(model::find_architecture_mismatch(ckpt), std::nullopt);
  EXPECT_EQ(ckpt.at("merge_s8.0.weight").dtype, "float16");
  EXPECT_EQ(ckpt.at("merge_s8.0.weight").data[100], 1.0f);
}

}  // namespace
}  // namespace neuflow::test
