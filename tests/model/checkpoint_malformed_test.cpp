// load_checkpoint on hostile and broken input: disallowed globals, damaged containers,
// inconsistent tensors, garbage pickles. Every case must end in a CheckpointError, never a
// crash, a hang or a huge allocation (run these under ASan too).
#include <gtest/gtest.h>

#include <random>

#include "checkpoint/pickle_reader.hpp"
#include "checkpoint_builder.hpp"
#include "neuflow/model/checkpoint.hpp"
#include "support/fixtures.hpp"
#include "support/temp_dir.hpp"

namespace neuflow::test {
namespace {

using model::CheckpointError;
using model::load_checkpoint;
using Kind = CheckpointError::Kind;

// Loads `path`, expecting a CheckpointError of `kind` whose message contains `needle`.
void expect_error(const std::filesystem::path& path, Kind kind, const std::string& needle) {
  try {
    (void)load_checkpoint(path);
    ADD_FAILURE() << "loading " << path << " succeeded; expected an error about '" << needle << "'";
  } catch (const CheckpointError& e) {
    const std::string message = e.what();
    EXPECT_EQ(static_cast<int>(e.kind()), static_cast<int>(kind)) << message;
    EXPECT_NE(message.find(needle), std::string::npos) << message;
    EXPECT_NE(message.find(path.string()), std::string::npos) << "message must name the file: " << message;
  }
}

// Loads `path` and accepts success or a CheckpointError; anything else fails the test.
void expect_no_crash(const std::filesystem::path& path) {
  try {
    (void)load_checkpoint(path);
  } catch (const CheckpointError&) {
  }
}

std::filesystem::path write_pickle(const TempDir& dir, const std::string& name, const std::string& pickle,
                                   std::vector<std::pair<std::string, std::string>> storages = {}) {
  FakeCheckpoint ckpt;
  ckpt.pickle_override = pickle;
  ckpt.storages = std::move(storages);
  ckpt.write(dir / name);
  return dir / name;
}

FakeCheckpoint small_checkpoint() {
  FakeCheckpoint ckpt;
  ckpt.wrapper = Wrapper::kOrderedDictWithMetadata;
  ckpt.tensors = {
      {.name = "a.weight", .storage_key = "0", .storage_numel = 4, .size = {2, 2}},
      {.name = "a.bias", .storage_type = "HalfStorage", .storage_key = "1", .storage_numel = 2, .size = {2}}};
  ckpt.storages = {{"0", le_floats({1, 2, 3, 4})}, {"1", le_u16({0x3c00, 0x4000})}};
  return ckpt;
}

// --- security --------------------------------------------------------------------------------

// A pickle that would run `touch <marker>` under pickle.load.
std::string exploit(const std::string& module, const std::string& name, const std::string& marker, bool stack_global) {
  PickleWriter w;
  w.proto(stack_global ? 4 : 2);
  if (stack_global) {
    w.stack_global(module, name);
  } else {
    w.global(module, name);
  }
  w.str("touch " + marker).tuple1().reduce().stop();
  return w.bytes();
}

TEST(CheckpointSecurity, DisallowedGlobalsAreRejectedByName) {
  const std::pair<std::string, std::string> globals[] = {
      {"os", "system"},
      {"posix", "system"},
      {"builtins", "eval"},
      {"builtins", "exec"},
      {"subprocess", "Popen"},
      {"__builtin__", "getattr"},
      {"torch", "load"},
      {"torch._utils", "_rebuild_tensor"},
      {"collections", "defaultdict"},
      {"torch.serialization", "_get_layout"},
  };
  for (const bool stack_global : {false, true}) {
    for (const auto& [module, name] : globals) {
      SCOPED_TRACE(module + "." + name + (stack_global ? " via STACK_GLOBAL" : " via GLOBAL"));
      TempDir dir;
      const auto marker = dir / "pwned";
      const auto path = write_pickle(dir, "evil.pth", exploit(module, name, marker.string(), stack_global));
      expect_error(path, Kind::kUnsafe, "disallowed global '" + module + "." + name + "'");
      EXPECT_FALSE(std::filesystem::exists(marker));
    }
  }
}

TEST(CheckpointSecurity, DisallowedGlobalInsideAnotherEntryIsRejected) {
  // A valid state dict under 'model', and an exploit hidden in a sibling entry.
  TempDir dir;
  PickleWriter w;
  w.proto(2).empty_dict().str("model").empty_dict().setitem();
  w.str("optimizer").global("builtins", "eval").str("1+1").tuple1().reduce().setitem().stop();
  expect_error(write_pickle(dir, "evil.pth", w.bytes()), Kind::kUnsafe, "builtins.eval");
}

TEST(CheckpointSecurity, GlobalNamesWithControlCharactersAreEscaped) {
  TempDir dir;
  PickleWriter w;
  w.proto(2).global("os\x1b[2J", "system").stop();
  expect_error(write_pickle(dir, "evil.pth", w.bytes()), Kind::kUnsafe, "os\\x1b[2J.system");
}

TEST(CheckpointSecurity, AllowedGlobalsCannotBeCalledArbitrarily) {
  TempDir dir;
  {
    PickleWriter w;  // torch.FloatStorage("...")
    w.proto(2).global("torch", "FloatStorage").str("x").tuple1().reduce().stop();
    expect_error(write_pickle(dir, "a.pth", w.bytes()), Kind::kUnsupported, "torch.FloatStorage");
  }
  {
    PickleWriter w;  // OrderedDict([...]) with arguments
    w.proto(2).global("collections", "OrderedDict").empty_list().tuple1().reduce().stop();
    expect_error(write_pickle(dir, "b.pth", w.bytes()), Kind::kUnsupported, "OrderedDict");
  }
  {
    PickleWriter w;  // _rebuild_tensor_v2 with a string instead of a storage
    w.proto(2).global("torch._utils", "_rebuild_tensor_v2").mark().str("s").integer(0);
    w.empty_tuple().empty_tuple().boolean(false).none().tuple().reduce().stop();
    expect_error(write_pickle(dir, "c.pth", w.bytes()), Kind::kFormat, "storage is a str");
  }
  {
    PickleWriter w;  // REDUCE on a non-callable
    w.proto(2).str("os.system").empty_tuple().reduce().stop();
    expect_error(write_pickle(dir, "d.pth", w.bytes()), Kind::kFormat, "REDUCE on a str");
  }
}

TEST(CheckpointSecurity, UnsupportedOpcodesAreRejected) {
  // INST and OBJ instantiate classes, EXT1 uses the extension registry, PERSID (text form).
  for (const std::string op : {"i", "o", "\x82", "P", "I", "c"}) {
    SCOPED_TRACE(op);
    TempDir dir;
    PickleWriter w;
    w.proto(2).raw(op).raw("os\nsystem\n").stop();
    try {
      (void)load_checkpoint(write_pickle(dir, "op.pth", w.bytes()));
      ADD_FAILURE() << "accepted";
    } catch (const CheckpointError& e) {
      EXPECT_NE(e.kind(), Kind::kIo);
    }
  }
}

// --- container -------------------------------------------------------------------------------

TEST(CheckpointMalformed, MissingFileAndDirectory) {
  TempDir dir;
  expect_error(dir / "absent.pth", Kind::kIo, "no such file");
  expect_error(dir.path(), Kind::kIo, "directory");
}

TEST(CheckpointMalformed, NotACheckpoint) {
  TempDir dir;
  write_file(dir / "text.pth", "hello, this is not a checkpoint\n");
  expect_error(dir / "text.pth", Kind::kFormat, "not a PyTorch checkpoint");
  write_file(dir / "empty.pth", "");
  expect_error(dir / "empty.pth", Kind::kFormat, "empty file");
  write_file(dir / "tiny.pth", "PK");
  expect_error(dir / "tiny.pth", Kind::kFormat, "not a PyTorch checkpoint");
}

TEST(CheckpointMalformed, LegacyFormatIsExplained) {
  TempDir dir;
  // The legacy format starts with a protocol-2 pickle of torch's magic number.
  write_file(dir / "legacy.pth", std::string("\x80\x02\x8a\x0a\x6c\xfc\x9c\x46\xf9\x20\x6a\xa8\x50"
                                             "\x19.\x80\x02M\xe9\x03.",
                                             21));
  expect_error(dir / "legacy.pth", Kind::kUnsupported, "legacy");
  expect_error(dir / "legacy.pth", Kind::kUnsupported, "torch.save(torch.load(");
}

TEST(CheckpointMalformed, ZipWithoutDataPkl) {
  TempDir dir;
  write_zip(dir / "nopkl.pth", {{"archive/data/0", le_floats({1})}, {"archive/version", "3\n"}});
  expect_error(dir / "nopkl.pth", Kind::kFormat, "data.pkl");
  write_zip(dir / "nested.pth", {{"a/b/data.pkl", "x"}});
  expect_error(dir / "nested.pth", Kind::kFormat, "data.pkl");
  write_zip(dir / "two.pth", {{"a/data.pkl", "x"}, {"b/data.pkl", "y"}});
  expect_error(dir / "two.pth", Kind::kFormat, "several data.pkl");
}

TEST(CheckpointMalformed, MissingStorageEntry) {
  TempDir dir;
  FakeCheckpoint ckpt = small_checkpoint();
  ckpt.storages.pop_back();
  ckpt.write(dir / "m.pth");
  expect_error(dir / "m.pth", Kind::kFormat, "'archive/data/1'");
}

TEST(CheckpointMalformed, StorageSmallerThanDeclared) {
  TempDir dir;
  FakeCheckpoint ckpt = small_checkpoint();
  ckpt.storages[0].second.resize(10);  // 2.5 floats of 4
  ckpt.write(dir / "s.pth");
  expect_error(dir / "s.pth", Kind::kFormat, "storage '0' declares 4 float32 elements");
}

TEST(CheckpointMalformed, TensorOutsideItsStorage) {
  TempDir dir;
  const struct {
    FakeTensor tensor;
    std::string needle;
  } cases[] = {
      {{.name = "big", .storage_key = "0", .storage_numel = 4, .size = {5}}, "does not fit"},
      {{.name = "off", .storage_key = "0", .storage_numel = 4, .offset = 3, .size = {2}}, "does not fit"},
      {{.name = "far", .storage_key = "0", .storage_numel = 4, .offset = 9, .size = {0}}, "beyond its storage"},
      {{.name = "stride", .storage_key = "0", .storage_numel = 4, .size = {2, 2}, .stride = {3, 1}}, "does not fit"},
      {{.name = "huge", .storage_key = "0", .storage_numel = 4, .size = {1000000, 1000000}}, "does not fit"},
      {{.name = "bcast", .storage_key = "0", .storage_numel = 4, .size = {1000000, 1000000}, .stride = {0, 0}},
       "more elements than its storage"},
      {{.name = "overflow",
        .storage_key = "0",
        .storage_numel = 4,
        .size = {int64_t{1} << 31, int64_t{1} << 31, int64_t{1} << 31},
        .stride = {1, 1, 1}},
       "absurdly large"},
      {{.name = "wrap", .storage_key = "0", .storage_numel = 4, .size = {2}, .stride = {int64_t{1} << 62}},
       "does not fit"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.tensor.name);
    FakeCheckpoint ckpt;
    ckpt.tensors = {c.tensor};
    ckpt.storages = {{"0", le_floats({1, 2, 3, 4})}};
    ckpt.write(dir / "t.pth");
    expect_error(dir / "t.pth", c.needle == "more elements than its storage" ? Kind::kUnsupported : Kind::kFormat,
                 c.needle);
  }
}

TEST(CheckpointMalformed, AbsurdStorageSizeDoesNotAllocate) {
  // A persistent id claiming 1e12 elements with 16 bytes of data: refused before reading.
  TempDir dir;
  FakeCheckpoint ckpt;
  ckpt.tensors = {
      {.name = "t", .storage_key = "0", .storage_numel = 1'000'000'000'000, .size = {1'000'000, 1'000'000}}};
  ckpt.storages = {{"0", le_floats({1, 2, 3, 4})}};
  ckpt.write(dir / "a.pth");
  expect_error(dir / "a.pth", Kind::kFormat, "declares 1000000000000 float32 elements");
}

TEST(CheckpointMalformed, StorageDeclaredTwiceWithDifferentSizes) {
  TempDir dir;
  FakeCheckpoint ckpt;
  ckpt.tensors = {{.name = "a", .storage_key = "0", .storage_numel = 4, .size = {4}},
                  {.name = "b", .storage_key = "0", .storage_numel = 2, .size = {2}}};
  ckpt.storages = {{"0", le_floats({1, 2, 3, 4})}};
  ckpt.write(dir / "d.pth");
  expect_error(dir / "d.pth", Kind::kFormat, "different sizes");
}

TEST(CheckpointMalformed, TruncatedFixture) {
  NEUFLOW_REQUIRE_FIXTURE(fixture, "neuflow-v2-seed0/checkpoint.pth");
  const std::string bytes = read_file(fixture);
  TempDir dir;
  for (const std::size_t n : {std::size_t{1}, std::size_t{4}, std::size_t{30}, std::size_t{100}, std::size_t{17000},
                              std::size_t{20000}, bytes.size() / 2, bytes.size() - 100, bytes.size() - 1}) {
    SCOPED_TRACE(n);
    write_file(dir / "cut.pth", std::string_view(bytes).substr(0, n));
    try {
      (void)load_checkpoint(dir / "cut.pth");
      ADD_FAILURE() << "a truncated checkpoint loaded";
    } catch (const CheckpointError& e) {
      EXPECT_EQ(e.kind(), Kind::kFormat) << e.what();
    }
  }
}

TEST(CheckpointMalformed, EveryTruncationOfASmallCheckpoint) {
  TempDir dir;
  small_checkpoint().write(dir / "full.pth");
  const std::string bytes = read_file(dir / "full.pth");
  ASSERT_NO_THROW((void)load_checkpoint(dir / "full.pth"));
  for (std::size_t n = 0; n < bytes.size(); ++n) {
    write_file(dir / "cut.pth", std::string_view(bytes).substr(0, n));
    EXPECT_THROW((void)load_checkpoint(dir / "cut.pth"), CheckpointError) << n;
  }
}

TEST(CheckpointMalformed, EverySingleByteCorruptionOfASmallCheckpoint) {
  TempDir dir;
  small_checkpoint().write(dir / "full.pth");
  const std::string bytes = read_file(dir / "full.pth");
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    for (const unsigned char x : {0x01, 0x80, 0xff}) {
      std::string damaged = bytes;
      damaged[i] = static_cast<char>(damaged[i] ^ x);
      write_file(dir / "bad.pth", damaged);
      expect_no_crash(dir / "bad.pth");
    }
  }
}

// --- pickle ----------------------------------------------------------------------------------

TEST(CheckpointMalformed, EveryTruncationOfThePickle) {
  const std::string pickle = small_checkpoint().pickle();
  const auto storages = small_checkpoint().storages;
  TempDir dir;
  for (std::size_t n = 0; n < pickle.size(); ++n) {
    SCOPED_TRACE(n);
    const auto path = write_pickle(dir, "p.pth", pickle.substr(0, n), storages);
    try {
      (void)load_checkpoint(path);
      ADD_FAILURE() << "a truncated pickle loaded";
    } catch (const CheckpointError& e) {
      EXPECT_EQ(e.kind(), Kind::kFormat) << e.what();
    }
  }
}

TEST(CheckpointMalformed, GarbagePickles) {
  TempDir dir;
  std::mt19937 rng(12345);
  const auto storages = small_checkpoint().storages;
  for (int round = 0; round < 300; ++round) {
    std::string garbage(1 + rng() % 200, '\0');
    for (auto& c : garbage) c = static_cast<char>(rng());
    if (round % 2 == 0) garbage = std::string("\x80\x02", 2) + garbage;
    expect_no_crash(write_pickle(dir, "g.pth", garbage, storages));
  }
  // Mutations of a valid pickle reach deeper into the reader.
  const std::string valid = small_checkpoint().pickle();
  for (int round = 0; round < 2000; ++round) {
    std::string mutated = valid;
    for (int k = 0; k < 1 + round % 4; ++k) {
      mutated[rng() % mutated.size()] = static_cast<char>(rng());
    }
    expect_no_crash(write_pickle(dir, "m.pth", mutated, storages));
  }
}

TEST(CheckpointMalformed, PickleStructureErrors) {
  TempDir dir;
  const struct {
    std::string name;
    std::string pickle;
    Kind kind;
    std::string needle;
  } cases[] = {
      {"no stop", PickleWriter().proto(2).empty_dict().bytes(), Kind::kFormat, "without a STOP"},
      {"underflow", PickleWriter().proto(2).setitem().bytes(), Kind::kFormat, "underflow"},
      {"empty stop", PickleWriter().proto(2).stop().bytes(), Kind::kFormat, "underflow"},
      {"bad memo", PickleWriter().proto(2).get(7).stop().bytes(), Kind::kFormat, "memo entry 7"},
      {"huge memo", PickleWriter().proto(2).empty_dict().put(0xfffffff0u).stop().bytes(), Kind::kFormat, "memo index"},
      {"no mark", PickleWriter().proto(2).empty_dict().setitems().bytes(), Kind::kFormat, "MARK"},
      {"odd setitems", PickleWriter().proto(2).empty_dict().mark().integer(1).setitems().bytes(), Kind::kFormat, "odd"},
      {"setitem on list", PickleWriter().proto(2).empty_list().integer(1).integer(2).setitem().bytes(), Kind::kFormat,
       "SETITEM(S) on a list"},
      {"append on dict", PickleWriter().proto(2).empty_dict().integer(1).append().bytes(), Kind::kFormat,
       "APPEND(S) on a dict"},
      {"huge string", PickleWriter().proto(2).raw(std::string("X\xff\xff\xff\xff", 5)).bytes(), Kind::kFormat,
       "exceeds the limit"},
      {"string past end",
       PickleWriter()
           .proto(2)
           .raw(std::string("X\x10\x00\x00\x00"
                            "ab",
                            7))
           .bytes(),
       Kind::kFormat, "truncated"},
      {"long1 too long",
       PickleWriter().proto(2).raw(std::string("\x8a\x09", 2)).raw(std::string(9, '\x01')).stop().bytes(),
       Kind::kUnsupported, "LONG1"},
      {"protocol 6", PickleWriter().proto(6).stop().bytes(), Kind::kUnsupported, "protocol 6"},
      {"protocol 1", PickleWriter().proto(1).stop().bytes(), Kind::kUnsupported, "protocol 1"},
      {"endless global", PickleWriter().proto(2).raw("ctorch\n").raw(std::string(1000, 'a')).bytes(), Kind::kFormat,
       "GLOBAL"},
      {"top-level list", PickleWriter().proto(2).empty_list().stop().bytes(), Kind::kUnsupported,
       "is a list, not a dict"},
      {"int in state dict",
       PickleWriter()
           .proto(2)
           .empty_dict()
           .str("model")
           .empty_dict()
           .str("a.weight")
           .integer(5)
           .setitem()
           .setitem()
           .stop()
           .bytes(),
       Kind::kUnsupported, "'a.weight' is a int, not a tensor"},
      {"model is a list", PickleWriter().proto(2).empty_dict().str("model").empty_list().setitem().stop().bytes(),
       Kind::kUnsupported, "'model' is a list"},
      {"not a state dict", PickleWriter().proto(2).empty_dict().str("epoch").integer(3).setitem().stop().bytes(),
       Kind::kUnsupported, "neither a 'model' nor"},
      {"int key",
       PickleWriter()
           .proto(2)
           .empty_dict()
           .str("model")
           .empty_dict()
           .integer(3)
           .none()
           .setitem()
           .setitem()
           .stop()
           .bytes(),
       Kind::kFormat, "key of type int"},
      {"bad persistent id", PickleWriter().proto(2).str("x").binpersid().stop().bytes(), Kind::kFormat,
       "persistent id"},
      {"persid with evil key",
       PickleWriter()
           .proto(2)
           .mark()
           .str("storage")
           .global("torch", "FloatStorage")
           .str("../../etc/passwd")
           .str("cpu")
           .integer(1)
           .tuple()
           .binpersid()
           .stop()
           .bytes(),
       Kind::kFormat, "invalid storage key"},
      {"stop inside mark", PickleWriter().proto(2).none().mark().stop().bytes(), Kind::kFormat, "STOP inside"},
      {"build on list", PickleWriter().proto(2).empty_list().none().build().stop().bytes(), Kind::kUnsupported,
       "BUILD on a list"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    expect_error(write_pickle(dir, "p.pth", c.pickle), c.kind, c.needle);
  }
}

TEST(CheckpointMalformed, DeepMarksAndLongPicklesAreBounded) {
  TempDir dir;
  std::string marks = PickleWriter().proto(2).bytes() + std::string(5000, '(');
  expect_error(write_pickle(dir, "marks.pth", marks), Kind::kFormat, "nested too deeply");

  // A tuple nested 100000 deep: no recursion anywhere, so this is just an unsupported top level.
  PickleWriter deep;
  deep.proto(2).none();
  for (int i = 0; i < 100000; ++i) deep.tuple1();
  deep.stop();
  expect_error(write_pickle(dir, "deep.pth", deep.bytes()), Kind::kUnsupported, "tuple");

  // A list that contains itself: fine for an arena, rejected as a top level.
  PickleWriter cycle;
  cycle.proto(2).empty_list().put(0).get(0).append().stop();
  expect_error(write_pickle(dir, "cycle.pth", cycle.bytes()), Kind::kUnsupported, "list");
}

TEST(PickleReader, LimitsAreConfigurable) {
  using model::detail::PickleLimits;
  using model::detail::unpickle;
  const std::string p = PickleWriter().proto(2).mark().str("abc").integer(1).integer(2).tuple().stop().bytes();
  const auto* data = reinterpret_cast<const unsigned char*>(p.data());
  EXPECT_NO_THROW((void)unpickle(data, p.size()));
  PickleLimits small_strings;
  small_strings.max_string = 2;
  EXPECT_THROW((void)unpickle(data, p.size(), small_strings), CheckpointError);
  PickleLimits few_objects;
  few_objects.max_objects = 3;
  EXPECT_THROW((void)unpickle(data, p.size(), few_objects), CheckpointError);
  PickleLimits shallow_stack;
  shallow_stack.max_stack = 2;
  EXPECT_THROW((void)unpickle(data, p.size(), shallow_stack), CheckpointError);
  PickleLimits no_marks;
  no_marks.max_marks = 0;
  EXPECT_THROW((void)unpickle(data, p.size(), no_marks), CheckpointError);

  const auto result = unpickle(data, p.size());
  EXPECT_EQ(result.protocol(), 2);
  const auto* tuple = std::get_if<model::detail::TupleValue>(&result.root().v);
  ASSERT_NE(tuple, nullptr);
  ASSERT_EQ(tuple->items.size(), 3u);
  EXPECT_EQ(std::get<std::string>(tuple->items[0]->v), "abc");
  EXPECT_EQ(std::get<int64_t>(tuple->items[2]->v), 2);
}

TEST(PickleReader, IntegersAndFloats) {
  using model::detail::unpickle;
  PickleWriter w;
  w.proto(2).mark();
  const int64_t values[] = {
      0, 255, 256, 65535, 65536, -1, INT32_MIN, INT32_MAX, int64_t{1} << 40, -(int64_t{1} << 40), INT64_MAX, INT64_MIN};
  for (const int64_t v : values) w.integer(v);
  w.raw(std::string("\x8a\x00", 2));  // LONG1 of zero bytes: 0
  w.real(-1.5).boolean(true).none().tuple().stop();
  const auto result = unpickle(reinterpret_cast<const unsigned char*>(w.bytes().data()), w.bytes().size());
  const auto& items = std::get<model::detail::TupleValue>(result.root().v).items;
  ASSERT_EQ(items.size(), std::size(values) + 4);
  for (std::size_t i = 0; i < std::size(values); ++i) {
    EXPECT_EQ(std::get<int64_t>(items[i]->v), values[i]) << i;
  }
  EXPECT_EQ(std::get<int64_t>(items[std::size(values)]->v), 0);
  EXPECT_EQ(std::get<double>(items[std::size(values) + 1]->v), -1.5);
  EXPECT_TRUE(std::get<bool>(items[std::size(values) + 2]->v));
}

}  // namespace
}  // namespace neuflow::test
