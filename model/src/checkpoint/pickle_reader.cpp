#include "checkpoint/pickle_reader.hpp"

#include <cstring>
#include <string_view>

#include "neuflow/model/checkpoint.hpp"

namespace neuflow::model::detail {

const char* dtype_name(StorageDtype dtype) {
  switch (dtype) {
    case StorageDtype::kFloat32: return "float32";
    case StorageDtype::kFloat16: return "float16";
    case StorageDtype::kBFloat16: return "bfloat16";
    case StorageDtype::kFloat64: return "float64";
    case StorageDtype::kInt64: return "int64";
    case StorageDtype::kInt32: return "int32";
  }
  return "?";
}

std::size_t dtype_size(StorageDtype dtype) {
  switch (dtype) {
    case StorageDtype::kFloat16:
    case StorageDtype::kBFloat16: return 2;
    case StorageDtype::kFloat32:
    case StorageDtype::kInt32: return 4;
    case StorageDtype::kFloat64:
    case StorageDtype::kInt64: return 8;
  }
  return 0;
}

const char* type_name(const PickleValue& value) {
  static constexpr const char* kNames[] = {"None", "bool", "int",    "float",   "str",   "tuple",
                                           "list", "dict", "global", "storage", "tensor"};
  return kNames[value.v.index()];
}

namespace {

using Kind = CheckpointError::Kind;

// Printable rendering of untrusted text for messages: control and non-ASCII bytes escaped,
// at most `limit` bytes shown.
std::string printable(std::string_view text, std::size_t limit = 120) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  for (std::size_t i = 0; i < text.size() && i < limit; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c >= 0x20 && c < 0x7f && c != '\\') {
      out += static_cast<char>(c);
    } else {
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 15];
    }
  }
  if (text.size() > limit) out += "...";
  return out;
}

struct AllowedGlobal {
  std::string_view module;
  std::string_view name;
  Global global;
  StorageDtype dtype;
};

constexpr AllowedGlobal kAllowedGlobals[] = {
    {"collections", "OrderedDict", Global::kOrderedDict, StorageDtype::kFloat32},
    {"torch._utils", "_rebuild_tensor_v2", Global::kRebuildTensorV2, StorageDtype::kFloat32},
    {"torch._utils", "_rebuild_parameter", Global::kRebuildParameter, StorageDtype::kFloat32},
    {"torch", "FloatStorage", Global::kStorageType, StorageDtype::kFloat32},
    {"torch", "HalfStorage", Global::kStorageType, StorageDtype::kFloat16},
    {"torch", "BFloat16Storage", Global::kStorageType, StorageDtype::kBFloat16},
    {"torch", "DoubleStorage", Global::kStorageType, StorageDtype::kFloat64},
    {"torch", "LongStorage", Global::kStorageType, StorageDtype::kInt64},
    {"torch", "IntStorage", Global::kStorageType, StorageDtype::kInt32},
};

}  // namespace

class Unpickler {
 public:
  Unpickler(const unsigned char* data, std::size_t size, const PickleLimits& limits)
      : data_(data), size_(size), limits_(limits) {}

  Unpickled run() {
    while (true) {
      op_pos_ = pos_;
      const auto op = static_cast<unsigned char>(u8());
      switch (op) {
        case 0x80: {  // PROTO
          const int protocol = u8();
          if (protocol < 2 || protocol > 5) {
            fail(Kind::kUnsupported, "pickle protocol " + std::to_string(protocol) + " (supported: 2 to 5)");
          }
          out_.protocol_ = protocol;
          break;
        }
        case 0x95:  // FRAME (protocol 4+): a length hint only
          take(8);
          break;
        case '}': push(make(DictValue{})); break;   // EMPTY_DICT
        case ']': push(make(ListValue{})); break;   // EMPTY_LIST
        case ')': push(make(TupleValue{})); break;  // EMPTY_TUPLE
        case 'N': push(make(NoneValue{})); break;   // NONE
        case 0x88: push(make(true)); break;         // NEWTRUE
        case 0x89: push(make(false)); break;        // NEWFALSE
        case '(':                                   // MARK
          if (marks_.size() >= limits_.max_marks) fail(Kind::kFormat, "MARKs nested too deeply");
          marks_.push_back(stack_.size());
          break;
        case 'X': push(make(string(u32()))); break;   // BINUNICODE
        case 0x8c: push(make(string(u8()))); break;   // SHORT_BINUNICODE
        case 0x8d: push(make(string(u64()))); break;  // BINUNICODE8
        case 'K': push(make(int64_t{u8()})); break;   // BININT1
        case 'M': push(make(int64_t{u16()})); break;  // BININT2
        case 'J':                                     // BININT
          push(make(int64_t{static_cast<int32_t>(u32())}));
          break;
        case 0x8a: push(make(long1())); break;    // LONG1
        case 'G': push(make(binfloat())); break;  // BINFLOAT
        case 'q': memo_put(u8()); break;          // BINPUT
        case 'r': memo_put(u32()); break;         // LONG_BINPUT
        case 0x94: memo_put(memo_count_); break;  // MEMOIZE: index len(memo)
        case 'h': push(memo_get(u8())); break;    // BINGET
        case 'j': push(memo_get(u32())); break;   // LONG_BINGET
        case 't': {                               // TUPLE
          TupleValue tuple{pop_mark()};
          push(make(std::move(tuple)));
          break;
        }
        case 0x85: tuple_n(1); break;  // TUPLE1
        case 0x86: tuple_n(2); break;  // TUPLE2
        case 0x87: tuple_n(3); break;  // TUPLE3
        case 's': {                    // SETITEM
          const PickleValue* value = pop();
          const PickleValue* key = pop();
          dict_at_top().entries.emplace_back(key, value);
          break;
        }
        case 'u': {  // SETITEMS
          const auto items = pop_mark();
          if (items.size() % 2 != 0) fail(Kind::kFormat, "SETITEMS with an odd number of items");
          auto& dict = dict_at_top();
          for (std::size_t i = 0; i < items.size(); i += 2) {
            dict.entries.emplace_back(items[i], items[i + 1]);
          }
          break;
        }
        case 'a': {  // APPEND
          const PickleValue* value = pop();
          list_at_top().items.push_back(value);
          break;
        }
        case 'e': {  // APPENDS
          const auto items = pop_mark();
          auto& list = list_at_top();
          list.items.insert(list.items.end(), items.begin(), items.end());
          break;
        }
        case 'c': {  // GLOBAL "module\nname\n"
          const std::string module = line();
          const std::string name = line();
          push(global(module, name));
          break;
        }
        case 0x93: {  // STACK_GLOBAL
          const PickleValue* name = pop();
          const PickleValue* module = pop();
          const auto* m = std::get_if<std::string>(&module->v);
          const auto* n = std::get_if<std::string>(&name->v);
          if (m == nullptr || n == nullptr) fail(Kind::kFormat, "STACK_GLOBAL needs two strings");
          push(global(*m, *n));
          break;
        }
        case 'R': {  // REDUCE
          const PickleValue* args = pop();
          const PickleValue* callable = pop();
          push(reduce(*callable, *args));
          break;
        }
        case 'Q': push(persistent_id(*pop())); break;  // BINPERSID
        case 'b': {                                    // BUILD
          const PickleValue* state = pop();
          build(top(), *state);
          break;
        }
        case '.': {  // STOP
          if (!marks_.empty()) fail(Kind::kFormat, "STOP inside an open MARK");
          out_.root_ = pop();
          return std::move(out_);
        }
        default:
          fail(Kind::kUnsupported, "pickle opcode 0x" + hex(op) + describe(op) + ", which a state dict does not use");
      }
    }
  }

 private:
  [[noreturn]] void fail(Kind kind, const std::string& message) const {
    throw CheckpointError(kind, "data.pkl: " + message + " (at byte " + std::to_string(op_pos_) + ")");
  }

  static std::string hex(unsigned v) {
    static constexpr char kHex[] = "0123456789abcdef";
    return {kHex[(v >> 4) & 15], kHex[v & 15]};
  }
  static std::string describe(unsigned char op) {
    if (op >= 0x20 && op < 0x7f) return std::string(" ('") + static_cast<char>(op) + "')";
    return {};
  }

  // --- reading -------------------------------------------------------------------------
  const unsigned char* take(std::size_t n) {
    if (n > size_ - pos_) {
      throw CheckpointError(Kind::kFormat, "data.pkl: truncated pickle (an opcode at byte " + std::to_string(op_pos_) +
                                               " needs " + std::to_string(n) + " more bytes, " +
                                               std::to_string(size_ - pos_) + " left)");
    }
    const unsigned char* p = data_ + pos_;
    pos_ += n;
    return p;
  }
  unsigned u8() {
    if (pos_ >= size_) {
      throw CheckpointError(Kind::kFormat, "data.pkl: truncated pickle (ends at byte " + std::to_string(size_) +
                                               " without a STOP opcode)");
    }
    return data_[pos_++];
  }
  uint64_t le(std::size_t n) {
    const unsigned char* p = take(n);
    uint64_t v = 0;
    for (std::size_t i = 0; i < n; ++i) v |= uint64_t{p[i]} << (8 * i);
    return v;
  }
  unsigned u16() { return static_cast<unsigned>(le(2)); }
  uint32_t u32() { return static_cast<uint32_t>(le(4)); }
  uint64_t u64() { return le(8); }

  std::string string(uint64_t n) {
    if (n > limits_.max_string) {
      fail(Kind::kFormat,
           "string of " + std::to_string(n) + " bytes exceeds the limit of " + std::to_string(limits_.max_string));
    }
    const unsigned char* p = take(static_cast<std::size_t>(n));
    return std::string(reinterpret_cast<const char*>(p), static_cast<std::size_t>(n));
  }

  std::string line() {
    constexpr std::size_t kMaxLine = 256;
    std::string text;
    while (true) {
      if (pos_ >= size_) fail(Kind::kFormat, "truncated pickle inside GLOBAL");
      const char c = static_cast<char>(data_[pos_++]);
      if (c == '\n') return text;
      if (text.size() >= kMaxLine) fail(Kind::kFormat, "GLOBAL name too long");
      text += c;
    }
  }

  int64_t long1() {
    const unsigned n = u8();
    if (n > 8) fail(Kind::kUnsupported, "integer of " + std::to_string(n) + " bytes (LONG1)");
    if (n == 0) return 0;
    uint64_t v = le(n);
    if (n < 8 && (v >> (8 * n - 1)) != 0) v |= ~uint64_t{0} << (8 * n);  // sign-extend
    return static_cast<int64_t>(v);
  }

  double binfloat() {
    const unsigned char* p = take(8);
    uint64_t bits = 0;
    for (int i = 0; i < 8; ++i) bits = (bits << 8) | p[i];  // big-endian
    double d;
    std::memcpy(&d, &bits, sizeof d);
    return d;
  }

  // --- values, stack, memo --------------------------------------------------------------
  template <class T>
  const PickleValue* make(T&& value) {
    if (out_.arena_.size() >= limits_.max_objects) {
      fail(Kind::kFormat, "more than " + std::to_string(limits_.max_objects) + " objects");
    }
    out_.arena_.push_back(PickleValue{std::forward<T>(value)});
    return &out_.arena_.back();
  }
  PickleValue* mutable_value(const PickleValue* value) {
    // Every value lives in our own arena; containers are filled in place.
    return const_cast<PickleValue*>(value);
  }

  void push(const PickleValue* value) {
    if (stack_.size() >= limits_.max_stack) fail(Kind::kFormat, "pickle stack too deep");
    stack_.push_back(value);
  }
  const PickleValue* pop() {
    if (stack_.empty() || (!marks_.empty() && stack_.size() <= marks_.back())) {
      fail(Kind::kFormat, "pickle stack underflow");
    }
    const PickleValue* value = stack_.back();
    stack_.pop_back();
    return value;
  }
  const PickleValue* top() {
    if (stack_.empty() || (!marks_.empty() && stack_.size() <= marks_.back())) {
      fail(Kind::kFormat, "pickle stack underflow");
    }
    return stack_.back();
  }
  std::vector<const PickleValue*> pop_mark() {
    if (marks_.empty()) fail(Kind::kFormat, "opcode needs a MARK but none is open");
    const std::size_t mark = marks_.back();
    marks_.pop_back();
    std::vector<const PickleValue*> items(stack_.begin() + static_cast<std::ptrdiff_t>(mark), stack_.end());
    stack_.resize(mark);
    return items;
  }
  void tuple_n(std::size_t n) {
    TupleValue tuple;
    tuple.items.resize(n);
    for (std::size_t i = n; i-- > 0;) tuple.items[i] = pop();
    push(make(std::move(tuple)));
  }
  DictValue& dict_at_top() {
    auto* dict = std::get_if<DictValue>(&mutable_value(top())->v);
    if (dict == nullptr) fail(Kind::kFormat, std::string("SETITEM(S) on a ") + type_name(*top()));
    return *dict;
  }
  ListValue& list_at_top() {
    auto* list = std::get_if<ListValue>(&mutable_value(top())->v);
    if (list == nullptr) fail(Kind::kFormat, std::string("APPEND(S) on a ") + type_name(*top()));
    return *list;
  }

  void memo_put(uint64_t index) {
    if (index >= limits_.max_memo) {
      fail(Kind::kFormat,
           "memo index " + std::to_string(index) + " exceeds the limit of " + std::to_string(limits_.max_memo));
    }
    const PickleValue* value = top();
    if (index >= memo_.size()) memo_.resize(static_cast<std::size_t>(index) + 1, nullptr);
    if (memo_[static_cast<std::size_t>(index)] == nullptr) ++memo_count_;
    memo_[static_cast<std::size_t>(index)] = value;
  }
  const PickleValue* memo_get(uint64_t index) {
    if (index >= memo_.size() || memo_[static_cast<std::size_t>(index)] == nullptr) {
      fail(Kind::kFormat, "memo entry " + std::to_string(index) + " was never stored");
    }
    return memo_[static_cast<std::size_t>(index)];
  }

  // --- the allow-listed semantics --------------------------------------------------------
  const PickleValue* global(const std::string& module, const std::string& name) {
    for (const auto& allowed : kAllowedGlobals) {
      if (allowed.module == module && allowed.name == name) {
        return make(GlobalRef{allowed.global, allowed.dtype, module + "." + name});
      }
    }
    fail(Kind::kUnsafe, "refusing disallowed global '" + printable(module) + "." + printable(name) +
                            "': a checkpoint may only reference collections.OrderedDict, "
                            "torch._utils._rebuild_tensor_v2, torch._utils._rebuild_parameter and torch "
                            "storage types; nothing from this file was executed");
  }

  static const TupleValue* as_tuple(const PickleValue& value) { return std::get_if<TupleValue>(&value.v); }

  std::vector<int64_t> int_tuple(const PickleValue& value, const char* what) {
    const auto* tuple = as_tuple(value);
    if (tuple == nullptr) {
      fail(Kind::kFormat, std::string("tensor ") + what + " is a " + type_name(value) + ", not a tuple");
    }
    if (tuple->items.size() > limits_.max_dims) {
      fail(Kind::kFormat,
           std::string("tensor ") + what + " has " + std::to_string(tuple->items.size()) + " dimensions");
    }
    std::vector<int64_t> out;
    for (const PickleValue* item : tuple->items) {
      const auto* v = std::get_if<int64_t>(&item->v);
      if (v == nullptr || *v < 0) {
        fail(Kind::kFormat, std::string("tensor ") + what + " holds a non-integer or negative entry");
      }
      out.push_back(*v);
    }
    return out;
  }

  const PickleValue* reduce(const PickleValue& callable, const PickleValue& args) {
    const auto* fn = std::get_if<GlobalRef>(&callable.v);
    const auto* tuple = as_tuple(args);
    if (fn == nullptr) fail(Kind::kFormat, std::string("REDUCE on a ") + type_name(callable));
    if (tuple == nullptr) fail(Kind::kFormat, "REDUCE arguments are not a tuple");
    const auto& a = tuple->items;
    switch (fn->global) {
      case Global::kOrderedDict:
        if (!a.empty()) fail(Kind::kUnsupported, "collections.OrderedDict called with arguments");
        return make(DictValue{});
      case Global::kRebuildTensorV2: {
        // (storage, storage_offset, size, stride, requires_grad, backward_hooks[, metadata])
        if (a.size() != 6 && a.size() != 7) {
          fail(Kind::kFormat, "_rebuild_tensor_v2 with " + std::to_string(a.size()) + " arguments (expected 6 or 7)");
        }
        const auto* storage = std::get_if<StorageRef>(&a[0]->v);
        if (storage == nullptr) {
          fail(Kind::kFormat, std::string("_rebuild_tensor_v2 storage is a ") + type_name(*a[0]));
        }
        const auto* offset = std::get_if<int64_t>(&a[1]->v);
        if (offset == nullptr || *offset < 0) {
          fail(Kind::kFormat, "_rebuild_tensor_v2 storage_offset is not a non-negative integer");
        }
        TensorRef tensor{storage, *offset, int_tuple(*a[2], "size"), int_tuple(*a[3], "stride")};
        if (tensor.size.size() != tensor.stride.size()) {
          fail(Kind::kFormat, "tensor size and stride differ in length");
        }
        return make(std::move(tensor));
      }
      case Global::kRebuildParameter:
        // (data, requires_grad, backward_hooks): the parameter is its tensor.
        if (a.size() != 3 || !std::holds_alternative<TensorRef>(a[0]->v)) {
          fail(Kind::kFormat, "_rebuild_parameter needs (tensor, requires_grad, hooks)");
        }
        return a[0];
      case Global::kStorageType: break;
    }
    fail(Kind::kUnsupported, "calling " + fn->name + " (only tensors are rebuilt)");
  }

  const PickleValue* persistent_id(const PickleValue& pid) {
    const auto* tuple = as_tuple(pid);
    if (tuple == nullptr || tuple->items.size() != 5) {
      fail(Kind::kFormat, "persistent id is not a 5-tuple ('storage', type, key, location, numel)");
    }
    const auto& a = tuple->items;
    const auto* tag = std::get_if<std::string>(&a[0]->v);
    const auto* type = std::get_if<GlobalRef>(&a[1]->v);
    const auto* key = std::get_if<std::string>(&a[2]->v);
    const auto* location = std::get_if<std::string>(&a[3]->v);
    const auto* numel = std::get_if<int64_t>(&a[4]->v);
    if (tag == nullptr || *tag != "storage") fail(Kind::kFormat, "persistent id is not a 'storage'");
    if (type == nullptr || type->global != Global::kStorageType) {
      fail(Kind::kFormat, "persistent id does not name a storage type");
    }
    if (key == nullptr || key->empty() || key->size() > 64) {
      fail(Kind::kFormat, "persistent id has an invalid storage key");
    }
    for (const char c : *key) {
      const bool ok = (c >= '0' && c <= '9') || (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_' ||
                      c == '-' || c == '.';
      if (!ok) fail(Kind::kFormat, "persistent id has an invalid storage key '" + printable(*key) + "'");
    }
    if (location == nullptr) fail(Kind::kFormat, "persistent id has no location string");
    if (numel == nullptr || *numel < 0) fail(Kind::kFormat, "persistent id has an invalid numel");
    return make(StorageRef{type->dtype, *key, *location, *numel});
  }

  void build(const PickleValue* target, const PickleValue& state) {
    // torch's OrderedDict state dicts carry a `_metadata` attribute, restored with BUILD; it
    // only holds module versions, which we do not need.
    if (!std::holds_alternative<DictValue>(target->v)) {
      fail(Kind::kUnsupported, std::string("BUILD on a ") + type_name(*target));
    }
    if (!std::holds_alternative<DictValue>(state.v) && !std::holds_alternative<NoneValue>(state.v) &&
        !std::holds_alternative<TupleValue>(state.v)) {
      fail(Kind::kUnsupported, std::string("BUILD with a ") + type_name(state) + " state");
    }
  }

  const unsigned char* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
  std::size_t op_pos_ = 0;
  PickleLimits limits_;
  Unpickled out_;
  std::vector<const PickleValue*> stack_;
  std::vector<std::size_t> marks_;
  std::vector<const PickleValue*> memo_;
  uint64_t memo_count_ = 0;  // distinct memo entries, as Python's len(memo)
};

Unpickled unpickle(const unsigned char* data, std::size_t size, const PickleLimits& limits) {
  return Unpickler(data, size, limits).run();
}

}  // namespace neuflow::model::detail
