#pragma once
// Hand-made PyTorch checkpoints for the loader tests: a pickle opcode emitter and a zip writer
// (libzip), so no binary blobs live in the repository.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace neuflow::test {

// Emits pickle opcodes; every method appends one opcode (with its argument).
class PickleWriter {
 public:
  PickleWriter& proto(int protocol = 2);
  PickleWriter& frame(uint64_t length);
  PickleWriter& raw(std::string_view bytes);
  PickleWriter& op(unsigned char opcode);
  PickleWriter& mark() { return op('('); }
  PickleWriter& tuple() { return op('t'); }
  PickleWriter& tuple1() { return op(0x85); }
  PickleWriter& tuple2() { return op(0x86); }
  PickleWriter& tuple3() { return op(0x87); }
  PickleWriter& empty_dict() { return op('}'); }
  PickleWriter& empty_list() { return op(']'); }
  PickleWriter& empty_tuple() { return op(')'); }
  PickleWriter& setitem() { return op('s'); }
  PickleWriter& setitems() { return op('u'); }
  PickleWriter& append() { return op('a'); }
  PickleWriter& appends() { return op('e'); }
  PickleWriter& reduce() { return op('R'); }
  PickleWriter& build() { return op('b'); }
  PickleWriter& binpersid() { return op('Q'); }
  PickleWriter& none() { return op('N'); }
  PickleWriter& boolean(bool v) { return op(v ? 0x88 : 0x89); }
  PickleWriter& memoize() { return op(0x94); }
  PickleWriter& stop() { return op('.'); }
  PickleWriter& str(std::string_view s);        // BINUNICODE
  PickleWriter& short_str(std::string_view s);  // SHORT_BINUNICODE
  PickleWriter& integer(int64_t v);             // BININT1/BININT2/BININT/LONG1, as pickle picks
  PickleWriter& real(double v);                 // BINFLOAT
  PickleWriter& global(std::string_view module, std::string_view name);        // GLOBAL
  PickleWriter& stack_global(std::string_view module, std::string_view name);  // STACK_GLOBAL
  PickleWriter& put(uint32_t index);                                           // BINPUT or LONG_BINPUT
  PickleWriter& get(uint32_t index);                                           // BINGET or LONG_BINGET

  const std::string& bytes() const { return bytes_; }

 private:
  std::string bytes_;
};

// One tensor of a hand-made state dict: a view into storage `storage_key`.
struct FakeTensor {
  std::string name;
  std::string storage_type = "FloatStorage";
  std::string storage_key;
  int64_t storage_numel = 0;
  int64_t offset = 0;
  std::vector<int64_t> size;
  std::vector<int64_t> stride;  // empty: contiguous
  bool as_parameter = false;    // wrap in torch._utils._rebuild_parameter
};

// Emits _rebuild_tensor_v2(...) (with its persistent id) for `t`, leaving the tensor on the stack.
void emit_tensor(PickleWriter& w, const FakeTensor& t);

enum class Wrapper { kModel, kStateDict, kBare, kOrderedDictWithMetadata, kModelWithExtras };

// The pickle of a state dict of `tensors`, wrapped as `wrapper`, protocol 2 as torch writes it.
std::string state_dict_pickle(const std::vector<FakeTensor>& tensors, Wrapper wrapper = Wrapper::kModel);

struct ZipEntry {
  std::string name;
  std::string data;
  bool compress = false;
};
// Writes a zip archive with the entries (stored unless compress is set). Throws on failure.
void write_zip(const std::filesystem::path& path, const std::vector<ZipEntry>& entries);

// The bytes of little-endian values.
std::string le_floats(const std::vector<float>& values);
std::string le_u16(const std::vector<uint16_t>& values);
std::string le_doubles(const std::vector<double>& values);
std::string le_i64(const std::vector<int64_t>& values);
std::string le_i32(const std::vector<int32_t>& values);

// A complete torch-style checkpoint: <folder>/data.pkl, <folder>/data/<key>..., version.
struct FakeCheckpoint {
  std::string folder = "archive";
  std::vector<FakeTensor> tensors;
  std::vector<std::pair<std::string, std::string>> storages;  // key -> bytes
  Wrapper wrapper = Wrapper::kModel;
  std::optional<std::string> pickle_override;  // used instead of state_dict_pickle(...)

  std::string pickle() const;
  std::vector<ZipEntry> entries() const;
  void write(const std::filesystem::path& path) const;
};

// A checkpoint with NeuFlow-V2's keys and shapes (values: a ramp), all tensors viewing one
// shared float storage (and one int64 storage for the counters), so the file stays small.
FakeCheckpoint fake_neuflow_checkpoint();

// NeuFlow-V2 with random weights as a freshly made PyTorch model has them (what the fixture
// checkpoint holds): convolution and linear weights and biases uniform in ±1/√fan-in, norms'
// scales 1 and shifts 0, BatchNorm's running mean 0 and variance 1. For checks that need a
// whole network where the fixtures are not (neuflow-gpu-check on a GPU machine).
FakeCheckpoint random_neuflow_checkpoint(std::uint32_t seed);

std::string read_file(const std::filesystem::path& path);
void write_file(const std::filesystem::path& path, std::string_view bytes);

}  // namespace neuflow::test
