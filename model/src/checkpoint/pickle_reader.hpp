#pragma once
// A restricted unpickler for PyTorch state dicts. Internal to neuflow_model.
//
// It implements only the opcodes torch.save emits for a state dict (protocols 2..5) and
// resolves only an allow-list of globals; nothing from the file is ever executed. REDUCE is
// interpreted for the allowed callables only (OrderedDict(), _rebuild_tensor_v2(...),
// _rebuild_parameter(...)); BINPERSID only for torch's ('storage', StorageType, key,
// location, numel) ids. All reads are bounds-checked and memo, stack, mark depth, string
// length and object count are bounded (PickleLimits). Errors are CheckpointError (kFormat for
// malformed input, kUnsafe for a disallowed global, kUnsupported for a valid but unsupported
// construct) with the byte offset of the offending opcode.
#include <cstddef>
#include <cstdint>
#include <deque>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace neuflow::model::detail {

enum class StorageDtype { kFloat32, kFloat16, kBFloat16, kFloat64, kInt64, kInt32 };
const char* dtype_name(StorageDtype dtype);  // "float32", ...
std::size_t dtype_size(StorageDtype dtype);  // bytes per element

// The callables and classes a state-dict pickle may name.
enum class Global {
  kOrderedDict,       // collections.OrderedDict
  kRebuildTensorV2,   // torch._utils._rebuild_tensor_v2
  kRebuildParameter,  // torch._utils._rebuild_parameter
  kStorageType,       // torch.<X>Storage; the dtype is in GlobalRef::dtype
};

struct PickleValue;

struct NoneValue {};
struct TupleValue {
  std::vector<const PickleValue*> items;
};
struct ListValue {
  std::vector<const PickleValue*> items;
};
struct DictValue {  // entries in insertion order; duplicates kept (the last one wins)
  std::vector<std::pair<const PickleValue*, const PickleValue*>> entries;
};
struct GlobalRef {
  Global global;
  StorageDtype dtype;  // kStorageType only
  std::string name;    // "module.name" as written in the pickle
};
// A persistent id ('storage', StorageType, key, location, numel).
struct StorageRef {
  StorageDtype dtype;
  std::string key;       // names the zip entry <folder>/data/<key>
  std::string location;  // "cpu", "cuda:0", ...
  int64_t numel;         // elements of dtype in the storage
};
// _rebuild_tensor_v2(storage, storage_offset, size, stride, ...): a view into a storage.
struct TensorRef {
  const StorageRef* storage;
  int64_t storage_offset;
  std::vector<int64_t> size;
  std::vector<int64_t> stride;
};

struct PickleValue {
  std::variant<NoneValue, bool, int64_t, double, std::string, TupleValue, ListValue, DictValue, GlobalRef, StorageRef,
               TensorRef>
      v;
};

struct PickleLimits {
  std::size_t max_objects = std::size_t{1} << 21;  // values created
  std::size_t max_memo = std::size_t{1} << 21;     // highest memo index + 1
  std::size_t max_stack = std::size_t{1} << 21;    // values on the stack
  std::size_t max_marks = 1024;                    // nested MARKs
  std::size_t max_string = std::size_t{1} << 20;   // bytes in one string
  std::size_t max_dims = 64;                       // tensor rank
};

// The result of unpickling: owns every value; root() is what STOP returned.
class Unpickled {
 public:
  const PickleValue& root() const { return *root_; }
  int protocol() const { return protocol_; }  // from PROTO; 0 when absent

 private:
  friend class Unpickler;
  std::deque<PickleValue> arena_;  // stable addresses; values refer to each other by pointer
  const PickleValue* root_ = nullptr;
  int protocol_ = 0;
};

Unpickled unpickle(const unsigned char* data, std::size_t size, const PickleLimits& limits = {});

// "dict", "tuple", "tensor", ... for messages.
const char* type_name(const PickleValue& value);

}  // namespace neuflow::model::detail
