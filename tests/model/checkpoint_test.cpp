// load_checkpoint on the shared fixture and on hand-made checkpoints: dtypes, views,
// wrappers, container variants.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>

#include "checkpoint_builder.hpp"
#include "neuflow/model/architecture.hpp"
#include "neuflow/model/checkpoint.hpp"
#include "support/fixtures.hpp"
#include "support/temp_dir.hpp"

namespace neuflow::test {
namespace {

using model::Checkpoint;
using model::CheckpointError;
using model::load_checkpoint;
using model::read_checkpoint_header;

// --- the fixture (a checkpoint in exactly the published format) -------------------------

TEST(CheckpointFixture, LoadsAllTensorsOfThePublishedFormat) {
  NEUFLOW_REQUIRE_FIXTURE(path, "neuflow-v2-seed0/checkpoint.pth");
  const auto start = std::chrono::steady_clock::now();
  const Checkpoint ckpt = load_checkpoint(path);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  RecordProperty("load_ms", std::to_string(ms));
  std::printf("fixture checkpoint loaded in %.1f ms\n", ms);

  EXPECT_EQ(ckpt.container, "PyTorch zip (folder 'checkpoint/'), pickle protocol 2");
  EXPECT_EQ(ckpt.wrapper, "model");
  EXPECT_FALSE(ckpt.stripped_module_prefix);
  // 155 tensors. (data.pkl holds 313 strings: 155 keys, 155 storage keys, 'model',
  // 'storage' and 'cpu'.)
  ASSERT_EQ(ckpt.keys.size(), 155u);
  EXPECT_EQ(ckpt.tensors.size(), 155u);
  EXPECT_EQ(ckpt.keys.front(), "backbone.block_8_1.conv1.weight");
  EXPECT_EQ(ckpt.keys.back(), "upsample_s8.conv3.bias");

  EXPECT_EQ(model::find_architecture_mismatch(ckpt), std::nullopt);
  const auto count = model::count_parameters(ckpt);
  EXPECT_EQ(count.parameters, 9'029'536);
  EXPECT_EQ(count.buffers, 5'385);
}

TEST(CheckpointFixture, KeysAreInTheArchitectureTablesOrder) {
  NEUFLOW_REQUIRE_FIXTURE(path, "neuflow-v2-seed0/checkpoint.pth");
  const Checkpoint ckpt = load_checkpoint(path);
  const auto& table = model::neuflow_v2_parameters();
  ASSERT_EQ(ckpt.keys.size(), table.size());
  for (std::size_t i = 0; i < table.size(); ++i) {
    EXPECT_EQ(ckpt.keys[i], table[i].name) << "at " << i;
    EXPECT_EQ(ckpt.at(table[i].name).shape, table[i].shape) << table[i].name;
  }
}

// The header alone: the same keys, shapes and dtypes as a full load, no data read.
TEST(CheckpointFixture, HeaderHasEveryTensorsShapeButNoData) {
  NEUFLOW_REQUIRE_FIXTURE(path, "neuflow-v2-seed0/checkpoint.pth");
  const Checkpoint full = load_checkpoint(path);
  const Checkpoint header = read_checkpoint_header(path);
  EXPECT_EQ(header.keys, full.keys);
  for (const auto& key : full.keys) {
    EXPECT_EQ(header.at(key).shape, full.at(key).shape) << key;
    EXPECT_EQ(header.at(key).dtype, full.at(key).dtype) << key;
    EXPECT_TRUE(header.at(key).data.empty()) << key;
  }
  EXPECT_EQ(model::find_architecture_mismatch(header), std::nullopt);
  EXPECT_THROW(read_checkpoint_header(path.parent_path() / "frame0.png"), CheckpointError);
}

TEST(CheckpointFixture, ValuesMatchTheRawStorages) {
  NEUFLOW_REQUIRE_FIXTURE(path, "neuflow-v2-seed0/checkpoint.pth");
  const Checkpoint ckpt = load_checkpoint(path);
  // Ground truth read with Python's zipfile + struct from checkpoint/data/N.
  const auto& w = ckpt.at("backbone.block_8_1.conv1.weight");
  EXPECT_EQ(w.dtype, "float32");
  ASSERT_EQ(w.data.size(), 49152u);
  EXPECT_EQ(w.data[0], -0.0024611065164208412f);
  EXPECT_EQ(w.data[12345], -0.01565283164381981f);
  EXPECT_EQ(w.data[49151], 0.0011496089864522219f);
  EXPECT_EQ(ckpt.at("upsample_s8.conv3.bias").data[575], -0.03553447127342224f);
  EXPECT_EQ(ckpt.at("backbone.block_8_1.norm1.running_var").data[0], 1.2883691787719727f);
  EXPECT_EQ(ckpt.at("backbone.block_cat_16.conv1.weight").data[1234], 0.019225310534238815f);
  const auto& counter = ckpt.at("backbone.block_8_1.norm1.num_batches_tracked");
  EXPECT_EQ(counter.dtype, "int64");
  EXPECT_TRUE(counter.shape.empty());
  ASSERT_EQ(counter.data.size(), 1u);
  EXPECT_EQ(counter.data[0], 1000.f);
  // Every running variance is positive and every value finite.
  for (const auto& [key, tensor] : ckpt.tensors) {
    for (const float v : tensor.data) ASSERT_TRUE(std::isfinite(v)) << key;
    if (key.ends_with("running_var")) {
      for (const float v : tensor.data) ASSERT_GT(v, 0.f) << key;
    }
  }
}

TEST(CheckpointFixture, AtNamesTheFileAndKey) {
  NEUFLOW_REQUIRE_FIXTURE(path, "neuflow-v2-seed0/checkpoint.pth");
  const Checkpoint ckpt = load_checkpoint(path);
  EXPECT_EQ(ckpt.find("no.such.key"), nullptr);
  try {
    (void)ckpt.at("no.such.key");
    FAIL() << "expected CheckpointError";
  } catch (const CheckpointError& e) {
    EXPECT_NE(std::string(e.what()).find("no.such.key"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("checkpoint.pth"), std::string::npos);
  }
}

// --- dtypes ----------------------------------------------------------------------------------

Checkpoint load_one(const TempDir& dir, const FakeTensor& tensor, const std::string& bytes) {
  FakeCheckpoint ckpt;
  ckpt.tensors = {tensor};
  ckpt.storages = {{tensor.storage_key, bytes}};
  ckpt.write(dir / "one.pth");
  return load_checkpoint(dir / "one.pth");
}

TEST(CheckpointDtypes, Float16IsConvertedExactly) {
  TempDir dir;
  const std::vector<uint16_t> bits = {0x3c00, 0xc000, 0x7bff, 0x0001, 0x03ff, 0x3800,
                                      0x8000, 0x7c00, 0xfc00, 0x3555, 0x0400};
  FakeTensor t{.name = "h", .storage_type = "HalfStorage", .storage_key = "0", .storage_numel = 11, .size = {11}};
  const Checkpoint ckpt = load_one(dir, t, le_u16(bits));
  const auto& h = ckpt.at("h");
  EXPECT_EQ(h.dtype, "float16");
  ASSERT_EQ(h.data.size(), bits.size());
  EXPECT_EQ(h.data[0], 1.0f);
  EXPECT_EQ(h.data[1], -2.0f);
  EXPECT_EQ(h.data[2], 65504.0f);
  EXPECT_EQ(h.data[3], std::ldexp(1.0f, -24));     // smallest subnormal
  EXPECT_EQ(h.data[4], std::ldexp(1023.0f, -24));  // largest subnormal
  EXPECT_EQ(h.data[5], 0.5f);
  EXPECT_EQ(h.data[6], 0.0f);
  EXPECT_TRUE(std::signbit(h.data[6]));
  EXPECT_EQ(h.data[7], std::numeric_limits<float>::infinity());
  EXPECT_EQ(h.data[8], -std::numeric_limits<float>::infinity());
  EXPECT_EQ(h.data[9], 0.333251953125f);
  EXPECT_EQ(h.data[10], std::ldexp(1.0f, -14));  // smallest normal
}

TEST(CheckpointDtypes, Float16NanStaysNan) {
  TempDir dir;
  FakeTensor t{.name = "h", .storage_type = "HalfStorage", .storage_key = "0", .storage_numel = 1, .size = {1}};
  EXPECT_TRUE(std::isnan(load_one(dir, t, le_u16({0x7e00})).at("h").data[0]));
}

TEST(CheckpointDtypes, BFloat16IsConvertedExactly) {
  TempDir dir;
  FakeTensor t{.name = "b", .storage_type = "BFloat16Storage", .storage_key = "7", .storage_numel = 4, .size = {2, 2}};
  const Checkpoint ckpt = load_one(dir, t, le_u16({0x3f80, 0xc040, 0x4049, 0x0000}));
  const auto& b = ckpt.at("b");
  EXPECT_EQ(b.dtype, "bfloat16");
  EXPECT_EQ(b.shape, (std::vector<int64_t>{2, 2}));
  EXPECT_EQ(b.data, (std::vector<float>{1.0f, -3.0f, 3.140625f, 0.0f}));
}

TEST(CheckpointDtypes, DoubleAndIntegersAreConverted) {
  TempDir dir;
  FakeCheckpoint ckpt;
  ckpt.tensors = {
      {.name = "d", .storage_type = "DoubleStorage", .storage_key = "0", .storage_numel = 3, .size = {3}},
      {.name = "l", .storage_type = "LongStorage", .storage_key = "1", .storage_numel = 2, .size = {2}},
      {.name = "i", .storage_type = "IntStorage", .storage_key = "2", .storage_numel = 2, .size = {2}},
  };
  ckpt.storages = {
      {"0", le_doubles({0.1, -1e300, 2.5})}, {"1", le_i64({-5, int64_t{1} << 40})}, {"2", le_i32({-7, 123456})}};
  ckpt.write(dir / "c.pth");
  const Checkpoint loaded = load_checkpoint(dir / "c.pth");
  EXPECT_EQ(loaded.at("d").dtype, "float64");
  EXPECT_EQ(loaded.at("d").data[0], 0.1f);
  EXPECT_EQ(loaded.at("d").data[1], -std::numeric_limits<float>::infinity());
  EXPECT_EQ(loaded.at("d").data[2], 2.5f);
  EXPECT_EQ(loaded.at("l").dtype, "int64");
  EXPECT_EQ(loaded.at("l").data, (std::vector<float>{-5.f, 1099511627776.f}));
  EXPECT_EQ(loaded.at("i").dtype, "int32");
  EXPECT_EQ(loaded.at("i").data, (std::vector<float>{-7.f, 123456.f}));
}

TEST(CheckpointDtypes, BigEndianStoragesAreSwapped) {
  TempDir dir;
  FakeCheckpoint ckpt;
  ckpt.tensors = {{.name = "f", .storage_key = "0", .storage_numel = 2, .size = {2}},
                  {.name = "h", .storage_type = "HalfStorage", .storage_key = "1", .storage_numel = 1, .size = {1}}};
  ckpt.storages = {{"0", std::string("\x3f\x80\x00\x00\xc0\x00\x00\x00", 8)}, {"1", std::string("\x3c\x00", 2)}};
  auto entries = ckpt.entries();
  entries.push_back({"archive/byteorder", "big"});
  write_zip(dir / "be.pth", entries);
  const Checkpoint loaded = load_checkpoint(dir / "be.pth");
  EXPECT_EQ(loaded.at("f").data, (std::vector<float>{1.0f, -2.0f}));
  EXPECT_EQ(loaded.at("h").data, (std::vector<float>{1.0f}));
  EXPECT_NE(loaded.container.find("big-endian"), std::string::npos);
}

// --- views -----------------------------------------------------------------------------------

std::vector<float> iota(int n) {
  std::vector<float> v(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) v[static_cast<std::size_t>(i)] = static_cast<float>(i);
  return v;
}

TEST(CheckpointViews, NonContiguousStridesAndOffsetsAreGathered) {
  TempDir dir;
  FakeCheckpoint ckpt;
  ckpt.tensors = {
      // The transpose of a 2x3 matrix [[0,1,2],[3,4,5]].
      {.name = "transposed", .storage_key = "0", .storage_numel = 12, .size = {3, 2}, .stride = {1, 3}},
      // A 2x2 window at offset 5 of a 3x4 matrix.
      {.name = "window", .storage_key = "0", .storage_numel = 12, .offset = 5, .size = {2, 2}, .stride = {4, 1}},
      // Every other element, from offset 1.
      {.name = "strided", .storage_key = "0", .storage_numel = 12, .offset = 1, .size = {6}, .stride = {2}},
      // A contiguous slice at an offset, and a 3-d permuted view.
      {.name = "slice", .storage_key = "0", .storage_numel = 12, .offset = 10, .size = {2}},
      {.name = "permuted", .storage_key = "0", .storage_numel = 12, .size = {2, 3, 2}, .stride = {1, 4, 2}},
      // A row broadcast over two rows (stride 0), within the storage's element count.
      {.name = "broadcast", .storage_key = "0", .storage_numel = 12, .size = {2, 3}, .stride = {0, 1}},
      // Zero-size and size-1 dimensions with arbitrary strides.
      {.name = "empty", .storage_key = "0", .storage_numel = 12, .size = {0, 4}},
      {.name = "ones",
       .storage_key = "0",
       .storage_numel = 12,
       .offset = 7,
       .size = {1, 1, 2},
       .stride = {99, 1000, 1}},
  };
  ckpt.storages = {{"0", le_floats(iota(12))}};
  ckpt.write(dir / "v.pth");
  const Checkpoint loaded = load_checkpoint(dir / "v.pth");
  EXPECT_EQ(loaded.at("transposed").data, (std::vector<float>{0, 3, 1, 4, 2, 5}));
  EXPECT_EQ(loaded.at("window").data, (std::vector<float>{5, 6, 9, 10}));
  EXPECT_EQ(loaded.at("strided").data, (std::vector<float>{1, 3, 5, 7, 9, 11}));
  EXPECT_EQ(loaded.at("slice").data, (std::vector<float>{10, 11}));
  EXPECT_EQ(loaded.at("permuted").data, (std::vector<float>{0, 2, 4, 6, 8, 10, 1, 3, 5, 7, 9, 11}));
  EXPECT_EQ(loaded.at("broadcast").data, (std::vector<float>{0, 1, 2, 0, 1, 2}));
  EXPECT_TRUE(loaded.at("empty").data.empty());
  EXPECT_EQ(loaded.at("empty").shape, (std::vector<int64_t>{0, 4}));
  EXPECT_EQ(loaded.at("ones").data, (std::vector<float>{7, 8}));
}

TEST(CheckpointViews, StridedHalfViews) {
  TempDir dir;
  FakeTensor t{.name = "h",
               .storage_type = "HalfStorage",
               .storage_key = "0",
               .storage_numel = 4,
               .offset = 1,
               .size = {2},
               .stride = {2}};
  const Checkpoint ckpt = load_one(dir, t, le_u16({0x3c00, 0x4000, 0x4200, 0x4400}));
  EXPECT_EQ(ckpt.at("h").data, (std::vector<float>{2.0f, 4.0f}));
}

TEST(CheckpointViews, ScalarTensor) {
  TempDir dir;
  FakeTensor t{.name = "s", .storage_key = "0", .storage_numel = 3, .offset = 2, .size = {}};
  const Checkpoint ckpt = load_one(dir, t, le_floats({1, 2, 3}));
  EXPECT_TRUE(ckpt.at("s").shape.empty());
  EXPECT_EQ(ckpt.at("s").numel(), 1);
  EXPECT_EQ(ckpt.at("s").data, (std::vector<float>{3}));
}

// --- wrappers and containers -----------------------------------------------------------------

FakeCheckpoint two_tensors() {
  FakeCheckpoint ckpt;
  ckpt.tensors = {{.name = "a.weight", .storage_key = "0", .storage_numel = 4, .size = {2, 2}},
                  {.name = "a.bias", .storage_key = "1", .storage_numel = 2, .size = {2}}};
  ckpt.storages = {{"0", le_floats({1, 2, 3, 4})}, {"1", le_floats({5, 6})}};
  return ckpt;
}

void expect_two_tensors(const Checkpoint& loaded) {
  EXPECT_EQ(loaded.keys, (std::vector<std::string>{"a.weight", "a.bias"}));
  EXPECT_EQ(loaded.at("a.weight").data, (std::vector<float>{1, 2, 3, 4}));
  EXPECT_EQ(loaded.at("a.bias").data, (std::vector<float>{5, 6}));
}

TEST(CheckpointWrappers, ModelStateDictBareAndExtras) {
  const std::pair<Wrapper, std::string> cases[] = {
      {Wrapper::kModel, "model"},
      {Wrapper::kStateDict, "state_dict"},
      {Wrapper::kBare, "bare"},
      {Wrapper::kOrderedDictWithMetadata, "model"},
      {Wrapper::kModelWithExtras, "model"},
  };
  for (const auto& [wrapper, name] : cases) {
    SCOPED_TRACE(name);
    TempDir dir;
    FakeCheckpoint ckpt = two_tensors();
    ckpt.wrapper = wrapper;
    ckpt.write(dir / "w.pth");
    const Checkpoint loaded = load_checkpoint(dir / "w.pth");
    EXPECT_EQ(loaded.wrapper, name);
    EXPECT_EQ(loaded.path, (dir / "w.pth").string());
    expect_two_tensors(loaded);
  }
}

TEST(CheckpointWrappers, BareStateDictWithATensorNamedModel) {
  TempDir dir;
  FakeCheckpoint ckpt = two_tensors();
  ckpt.tensors[0].name = "model";
  ckpt.wrapper = Wrapper::kBare;
  ckpt.write(dir / "b.pth");
  const Checkpoint loaded = load_checkpoint(dir / "b.pth");
  EXPECT_EQ(loaded.wrapper, "bare");
  EXPECT_EQ(loaded.keys, (std::vector<std::string>{"model", "a.bias"}));
}

TEST(CheckpointWrappers, ModulePrefixIsStrippedOnlyWhenOnEveryKey) {
  TempDir dir;
  FakeCheckpoint ckpt = two_tensors();
  for (auto& t : ckpt.tensors) t.name = "module." + t.name;
  ckpt.write(dir / "dp.pth");
  const Checkpoint loaded = load_checkpoint(dir / "dp.pth");
  EXPECT_TRUE(loaded.stripped_module_prefix);
  expect_two_tensors(loaded);

  ckpt.tensors[1].name = "a.bias";  // only one key prefixed: left alone
  ckpt.write(dir / "mixed.pth");
  const Checkpoint mixed = load_checkpoint(dir / "mixed.pth");
  EXPECT_FALSE(mixed.stripped_module_prefix);
  EXPECT_EQ(mixed.keys, (std::vector<std::string>{"module.a.weight", "a.bias"}));
}

TEST(CheckpointWrappers, AnyFolderName) {
  for (const std::string folder : {"archive", "neuflow_mixed", "x", "my.weights-v2"}) {
    SCOPED_TRACE(folder);
    TempDir dir;
    FakeCheckpoint ckpt = two_tensors();
    ckpt.folder = folder;
    ckpt.write(dir / "f.pth");
    const Checkpoint loaded = load_checkpoint(dir / "f.pth");
    EXPECT_EQ(loaded.container, "PyTorch zip (folder '" + folder + "/'), pickle protocol 2");
    expect_two_tensors(loaded);
  }
}

TEST(CheckpointWrappers, CompressedEntriesAreRead) {
  TempDir dir;
  FakeCheckpoint ckpt = two_tensors();
  auto entries = ckpt.entries();
  for (auto& e : entries) e.compress = true;
  write_zip(dir / "z.pth", entries);
  expect_two_tensors(load_checkpoint(dir / "z.pth"));
}

TEST(CheckpointWrappers, ParametersAndSharedStorages) {
  TempDir dir;
  FakeCheckpoint ckpt;
  ckpt.tensors = {{.name = "p", .storage_key = "0", .storage_numel = 6, .size = {3}, .as_parameter = true},
                  {.name = "q", .storage_key = "0", .storage_numel = 6, .offset = 3, .size = {3}}};
  ckpt.storages = {{"0", le_floats(iota(6))}};
  ckpt.write(dir / "p.pth");
  const Checkpoint loaded = load_checkpoint(dir / "p.pth");
  EXPECT_EQ(loaded.at("p").data, (std::vector<float>{0, 1, 2}));
  EXPECT_EQ(loaded.at("q").data, (std::vector<float>{3, 4, 5}));
}

TEST(CheckpointWrappers, RepeatedKeyKeepsTheLastValueAndFirstPosition) {
  TempDir dir;
  FakeCheckpoint ckpt = two_tensors();
  ckpt.tensors.push_back({.name = "a.weight", .storage_key = "1", .storage_numel = 2, .size = {2}});
  ckpt.write(dir / "r.pth");
  const Checkpoint loaded = load_checkpoint(dir / "r.pth");
  EXPECT_EQ(loaded.keys, (std::vector<std::string>{"a.weight", "a.bias"}));
  EXPECT_EQ(loaded.at("a.weight").data, (std::vector<float>{5, 6}));
}

TEST(CheckpointWrappers, Protocol4OpcodesAreUnderstood) {
  // What torch.save(..., pickle_protocol=4) emits: FRAME, SHORT_BINUNICODE, MEMOIZE,
  // STACK_GLOBAL, LONG_BINPUT/LONG_BINGET.
  TempDir dir;
  PickleWriter w;
  w.proto(4).frame(1000).empty_dict().memoize().short_str("state_dict").memoize();
  w.empty_dict().memoize().mark();
  w.short_str("w").stack_global("torch._utils", "_rebuild_tensor_v2").memoize();
  w.mark().mark().short_str("storage").stack_global("torch", "FloatStorage").put(300);
  w.short_str("0").short_str("cpu").integer(3).tuple().binpersid();
  w.integer(0).integer(3).tuple1().integer(1).tuple1().boolean(false);
  w.stack_global("collections", "OrderedDict").empty_tuple().reduce().tuple().reduce();
  w.short_str("v").get(3);  // memo 3 is _rebuild_tensor_v2 (via MEMOIZE)
  w.mark().mark().short_str("storage").get(300).short_str("0").short_str("cpu").integer(3);
  w.tuple().binpersid().integer(1).integer(2).tuple1().integer(1).tuple1().boolean(false).none();
  w.tuple().reduce();
  w.setitems().setitem().stop();
  FakeCheckpoint ckpt;
  ckpt.pickle_override = w.bytes();
  ckpt.storages = {{"0", le_floats({7, 8, 9})}};
  ckpt.write(dir / "p4.pth");
  const Checkpoint loaded = load_checkpoint(dir / "p4.pth");
  EXPECT_EQ(loaded.container, "PyTorch zip (folder 'archive/'), pickle protocol 4");
  EXPECT_EQ(loaded.wrapper, "state_dict");
  EXPECT_EQ(loaded.at("w").data, (std::vector<float>{7, 8, 9}));
  EXPECT_EQ(loaded.at("v").data, (std::vector<float>{8, 9}));
}

TEST(CheckpointWrappers, EmptyStateDict) {
  TempDir dir;
  FakeCheckpoint ckpt;
  ckpt.write(dir / "e.pth");
  const Checkpoint loaded = load_checkpoint(dir / "e.pth");
  EXPECT_TRUE(loaded.keys.empty());
  EXPECT_NE(model::find_architecture_mismatch(loaded), std::nullopt);
}

}  // namespace
}  // namespace neuflow::test
