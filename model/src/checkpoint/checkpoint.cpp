// load_checkpoint: the zip container, the restricted unpickler, and tensor materialization.
#include <bit>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <string_view>
#include <system_error>
#include <unordered_map>
#include <utility>

#include "checkpoint/pickle_reader.hpp"
#include "checkpoint/zip_archive.hpp"
#include "neuflow/model/checkpoint.hpp"

namespace neuflow::model {

namespace {

using Kind = CheckpointError::Kind;
using detail::DictValue;
using detail::PickleValue;
using detail::StorageDtype;
using detail::StorageRef;
using detail::TensorRef;

constexpr uint64_t kMaxPickleBytes = uint64_t{256} << 20;
// Far above any real network; keeps a lying header from driving an allocation.
constexpr int64_t kMaxDim = int64_t{1} << 40;

[[noreturn]] void fail(Kind kind, const std::string& message) { throw CheckpointError(kind, message); }

float half_to_float(uint16_t h) {
  const uint32_t sign = uint32_t{h & 0x8000u} << 16;
  const uint32_t exponent = (h >> 10) & 0x1f;
  uint32_t mantissa = h & 0x3ffu;
  uint32_t bits;
  if (exponent == 0x1f) {  // inf / nan
    bits = sign | 0x7f800000u | (mantissa << 13);
  } else if (exponent != 0) {  // normal
    bits = sign | ((exponent + 112) << 23) | (mantissa << 13);
  } else if (mantissa == 0) {  // zero
    bits = sign;
  } else {  // subnormal: renormalize
    uint32_t e = 113;
    while ((mantissa & 0x400u) == 0) {
      mantissa <<= 1;
      --e;
    }
    bits = sign | (e << 23) | ((mantissa & 0x3ffu) << 13);
  }
  return std::bit_cast<float>(bits);
}

// Reads little- or big-endian unsigned integers of 2, 4 or 8 bytes.
template <class U>
U load(const unsigned char* p, bool big_endian) {
  U v = 0;
  for (std::size_t i = 0; i < sizeof(U); ++i) {
    const std::size_t shift = big_endian ? (sizeof(U) - 1 - i) : i;
    v = static_cast<U>(v | (static_cast<U>(p[i]) << (8 * shift)));
  }
  return v;
}

float element(const unsigned char* p, StorageDtype dtype, bool big_endian) {
  switch (dtype) {
    case StorageDtype::kFloat32: return std::bit_cast<float>(load<uint32_t>(p, big_endian));
    case StorageDtype::kFloat16: return half_to_float(load<uint16_t>(p, big_endian));
    case StorageDtype::kBFloat16: return std::bit_cast<float>(uint32_t{load<uint16_t>(p, big_endian)} << 16);
    case StorageDtype::kFloat64: return static_cast<float>(std::bit_cast<double>(load<uint64_t>(p, big_endian)));
    case StorageDtype::kInt64: return static_cast<float>(static_cast<int64_t>(load<uint64_t>(p, big_endian)));
    case StorageDtype::kInt32: return static_cast<float>(static_cast<int32_t>(load<uint32_t>(p, big_endian)));
  }
  return 0.f;
}

// Converts `count` consecutive elements starting at `src`.
void convert_run(const unsigned char* src, std::size_t count, StorageDtype dtype, bool big_endian, float* dst) {
  if (dtype == StorageDtype::kFloat32 && big_endian == (std::endian::native == std::endian::big)) {
    std::memcpy(dst, src, count * sizeof(float));
    return;
  }
  const std::size_t step = detail::dtype_size(dtype);
  for (std::size_t i = 0; i < count; ++i) dst[i] = element(src + i * step, dtype, big_endian);
}

struct Storage {
  std::vector<unsigned char> bytes;
  int64_t numel = 0;
};

class Loader {
 public:
  // Without data, every tensor gets its shape and dtype and each storage's size is checked
  // against the zip entry, but no tensor data is read.
  Loader(const std::filesystem::path& path, bool with_data) : path_(path), with_data_(with_data) {}

  Checkpoint load() {
    check_file();
    detail::ZipArchive zip(path_);
    const std::string folder = find_folder(zip);
    if (const auto order = zip.size_of(folder + "byteorder"); order && *order <= 16) {
      const auto bytes = zip.read(folder + "byteorder", 16);
      const std::string text(bytes.begin(), bytes.end());
      if (text == "big") {
        big_endian_ = true;
      } else if (text != "little") {
        fail(Kind::kFormat, "unknown byteorder '" + text + "'");
      }
    }
    const auto pickle = zip.read(folder + "data.pkl", kMaxPickleBytes);
    const detail::Unpickled unpickled = detail::unpickle(pickle.data(), pickle.size());

    Checkpoint checkpoint;
    checkpoint.path = path_.string();
    checkpoint.container = "PyTorch zip (folder '" + folder + "'), pickle protocol " +
                           (unpickled.protocol() ? std::to_string(unpickled.protocol()) : std::string("unknown"));
    if (big_endian_) checkpoint.container += ", big-endian storages";

    const DictValue& state = find_state_dict(unpickled.root(), checkpoint.wrapper);
    std::vector<std::pair<std::string, const TensorRef*>> entries;
    entries.reserve(state.entries.size());
    for (const auto& [key_value, value] : state.entries) {
      const auto* key = std::get_if<std::string>(&key_value->v);
      if (key == nullptr) {
        fail(Kind::kFormat,
             std::string("state dict has a key of type ") + detail::type_name(*key_value) + " (expected str)");
      }
      const auto* tensor = std::get_if<TensorRef>(&value->v);
      if (tensor == nullptr) {
        fail(Kind::kUnsupported,
             "state dict entry '" + *key + "' is a " + detail::type_name(*value) + ", not a tensor");
      }
      entries.emplace_back(*key, tensor);
    }

    static constexpr std::string_view kPrefix = "module.";
    bool all_prefixed = !entries.empty();
    for (const auto& entry : entries) all_prefixed = all_prefixed && entry.first.starts_with(kPrefix);
    checkpoint.stripped_module_prefix = all_prefixed;

    for (auto& [key, ref] : entries) {
      if (all_prefixed) key.erase(0, kPrefix.size());
      CheckpointTensor tensor = with_data_ ? materialize(zip, folder, key, *ref) : describe(zip, folder, *ref);
      // A repeated key replaces the earlier value (Python dict semantics); order stays first-seen.
      const auto [it, inserted] = checkpoint.tensors.insert_or_assign(key, std::move(tensor));
      if (inserted) checkpoint.keys.push_back(key);
    }
    return checkpoint;
  }

 private:
  void check_file() {
    std::error_code ec;
    const auto status = std::filesystem::status(path_, ec);
    if (ec || !std::filesystem::exists(status)) fail(Kind::kIo, "no such file");
    if (std::filesystem::is_directory(status)) fail(Kind::kIo, "is a directory, not a file");
    std::ifstream in(path_, std::ios::binary);
    if (!in) fail(Kind::kIo, "cannot open the file for reading");
    unsigned char head[4] = {};
    in.read(reinterpret_cast<char*>(head), sizeof head);
    const auto got = in.gcount();
    if (got == 0) fail(Kind::kFormat, "empty file, not a PyTorch checkpoint");
    if (head[0] == 0x80 && got >= 2 && head[1] >= 2 && head[1] <= 5) {
      fail(Kind::kUnsupported,
           "legacy (pre-1.6, non-zip) PyTorch serialization format, which is not supported; "
           "re-save it with a recent PyTorch: torch.save(torch.load('in.pth', "
           "map_location='cpu', weights_only=True), 'out.pth')");
    }
    if (got < 4 || head[0] != 'P' || head[1] != 'K' || head[2] > 8 || head[3] > 8) {
      fail(Kind::kFormat, "not a PyTorch checkpoint (neither a zip archive nor a pickle)");
    }
  }

  // The folder holding data.pkl: torch names it after the file ('archive/' by default).
  static std::string find_folder(const detail::ZipArchive& zip) {
    std::vector<std::string> folders;
    for (const auto& name : zip.names()) {
      static constexpr std::string_view kPkl = "/data.pkl";
      if (name.size() > kPkl.size() && name.ends_with(kPkl) && name.find('/') == name.size() - kPkl.size()) {
        folders.push_back(name.substr(0, name.size() - kPkl.size() + 1));
      }
    }
    if (folders.empty()) {
      fail(Kind::kFormat, "zip archive has no '<folder>/data.pkl' entry: not a PyTorch checkpoint");
    }
    if (folders.size() > 1) {
      fail(Kind::kFormat, "zip archive has several data.pkl entries ('" + folders[0] + "', '" + folders[1] + "')");
    }
    return folders[0];
  }

  static const PickleValue* lookup(const DictValue& dict, std::string_view key) {
    const PickleValue* found = nullptr;
    for (const auto& [k, v] : dict.entries) {
      const auto* s = std::get_if<std::string>(&k->v);
      if (s != nullptr && *s == key) found = v;  // the last one wins, as in Python
    }
    return found;
  }

  static const DictValue& find_state_dict(const PickleValue& root, std::string& wrapper) {
    const auto* top = std::get_if<DictValue>(&root.v);
    if (top == nullptr) {
      fail(Kind::kUnsupported, std::string("the pickled object is a ") + detail::type_name(root) + ", not a dict");
    }
    for (const char* name : {"model", "state_dict"}) {
      const PickleValue* inner = lookup(*top, name);
      // A bare state dict may itself have a tensor named 'model'.
      if (inner != nullptr && !std::holds_alternative<TensorRef>(inner->v)) {
        const auto* dict = std::get_if<DictValue>(&inner->v);
        if (dict == nullptr) {
          fail(Kind::kUnsupported,
               std::string("entry '") + name + "' is a " + detail::type_name(*inner) + ", not a state dict");
        }
        wrapper = name;
        return *dict;
      }
    }
    for (const auto& entry : top->entries) {
      if (!std::holds_alternative<TensorRef>(entry.second->v)) {
        const auto* key = std::get_if<std::string>(&entry.first->v);
        fail(Kind::kUnsupported,
             "top-level dict has neither a 'model' nor a 'state_dict' entry and is not a state "
             "dict (entry '" +
                 (key ? *key : std::string("?")) + "' is a " + detail::type_name(*entry.second) + ")");
      }
    }
    wrapper = "bare";
    return *top;
  }

  CheckpointTensor describe(const detail::ZipArchive& zip, const std::string& folder, const TensorRef& ref) const {
    const StorageRef& sref = *ref.storage;
    const std::string entry = folder + "data/" + sref.key;
    const auto size = zip.size_of(entry);
    if (!size) fail(Kind::kFormat, "zip entry '" + entry + "' (storage " + sref.key + ") is missing");
    if (static_cast<uint64_t>(sref.numel) > *size / detail::dtype_size(sref.dtype)) {
      fail(Kind::kFormat, "storage '" + sref.key + "' declares " + std::to_string(sref.numel) + " elements but '" +
                              entry + "' holds only " + std::to_string(*size) + " bytes");
    }
    CheckpointTensor tensor;
    tensor.shape = ref.size;
    tensor.dtype = detail::dtype_name(sref.dtype);
    return tensor;
  }

  const Storage& storage(const detail::ZipArchive& zip, const std::string& folder, const StorageRef& ref) {
    if (auto it = storages_.find(ref.key); it != storages_.end()) {
      if (it->second.numel != ref.numel) {
        fail(Kind::kFormat, "storage '" + ref.key + "' is declared with different sizes");
      }
      return it->second;
    }
    const std::string entry = folder + "data/" + ref.key;
    const auto size = zip.size_of(entry);
    if (!size) fail(Kind::kFormat, "zip entry '" + entry + "' (storage " + ref.key + ") is missing");
    const uint64_t element_size = detail::dtype_size(ref.dtype);
    if (static_cast<uint64_t>(ref.numel) > *size / element_size) {
      fail(Kind::kFormat, "storage '" + ref.key + "' declares " + std::to_string(ref.numel) + " " +
                              detail::dtype_name(ref.dtype) + " elements but '" + entry + "' holds only " +
                              std::to_string(*size) + " bytes");
    }
    Storage s;
    s.bytes = zip.read(entry, *size);
    s.numel = ref.numel;
    return storages_.emplace(ref.key, std::move(s)).first->second;
  }

  CheckpointTensor materialize(const detail::ZipArchive& zip, const std::string& folder, const std::string& key,
                               const TensorRef& ref) {
    const StorageRef& sref = *ref.storage;
    const auto where = [&] { return "tensor '" + key + "' " + shape_text(ref.size); };

    // Element count, without overflow.
    int64_t numel = 1;
    for (const int64_t d : ref.size) {
      if (d > kMaxDim || (d != 0 && numel > std::numeric_limits<int64_t>::max() / d)) {
        fail(Kind::kFormat, where() + " is absurdly large");
      }
      numel *= d;
    }
    // The view must lie inside the storage: offset + sum((size-1)*stride) < storage numel.
    if (ref.storage_offset > sref.numel) {
      fail(Kind::kFormat, where() + " starts at offset " + std::to_string(ref.storage_offset) +
                              " beyond its storage '" + sref.key + "' of " + std::to_string(sref.numel) + " elements");
    }
    if (numel > 0) {
      int64_t last = ref.storage_offset;
      bool overflow = false;
      for (std::size_t i = 0; i < ref.size.size(); ++i) {
        int64_t extent = 0;
        overflow = overflow || __builtin_mul_overflow(ref.size[i] - 1, ref.stride[i], &extent) ||
                   __builtin_add_overflow(last, extent, &last);
      }
      if (overflow || last >= sref.numel) {
        fail(Kind::kFormat, where() + " (offset " + std::to_string(ref.storage_offset) + ", stride " +
                                shape_text(ref.stride) + ") does not fit in storage '" + sref.key + "' of " +
                                std::to_string(sref.numel) + " elements");
      }
    }
    // Broadcast views (stride 0) could claim more elements than the file holds; refuse those
    // rather than allocate for them.
    if (numel > sref.numel) {
      fail(Kind::kUnsupported,
           where() + " has more elements than its storage '" + sref.key + "' (" + std::to_string(sref.numel) + ")");
    }

    const Storage& st = storage(zip, folder, sref);
    CheckpointTensor tensor;
    tensor.shape = ref.size;
    tensor.dtype = detail::dtype_name(sref.dtype);
    tensor.data.resize(static_cast<std::size_t>(numel));
    if (numel == 0) return tensor;

    const std::size_t esize = detail::dtype_size(sref.dtype);
    const unsigned char* base = st.bytes.data();
    // Contiguous (C order, ignoring size-1 dims): one run.
    bool contiguous = true;
    int64_t expected = 1;
    for (std::size_t i = ref.size.size(); i-- > 0;) {
      if (ref.size[i] != 1 && ref.stride[i] != expected) contiguous = false;
      expected *= ref.size[i];
    }
    if (contiguous) {
      convert_run(base + static_cast<std::size_t>(ref.storage_offset) * esize, static_cast<std::size_t>(numel),
                  sref.dtype, big_endian_, tensor.data.data());
      return tensor;
    }
    // General strided view: walk the index space in C order (odometer on all but the last dim).
    const std::size_t rank = ref.size.size();
    std::vector<int64_t> index(rank, 0);
    const int64_t inner = ref.size[rank - 1];
    const int64_t inner_stride = ref.stride[rank - 1];
    float* out = tensor.data.data();
    int64_t offset = ref.storage_offset;  // of index (i0, ..., i_{r-2}, 0)
    for (int64_t done = 0; done < numel; done += inner) {
      for (int64_t j = 0; j < inner; ++j) {
        *out++ = element(base + static_cast<std::size_t>(offset + j * inner_stride) * esize, sref.dtype, big_endian_);
      }
      for (std::size_t d = rank - 1; d-- > 0;) {
        offset += ref.stride[d];
        if (++index[d] < ref.size[d]) break;
        offset -= ref.stride[d] * ref.size[d];
        index[d] = 0;
      }
    }
    return tensor;
  }

  std::filesystem::path path_;
  bool with_data_ = true;
  bool big_endian_ = false;
  std::unordered_map<std::string, Storage> storages_;
};

}  // namespace

std::string shape_text(const std::vector<int64_t>& shape) {
  std::string s = "[";
  for (std::size_t i = 0; i < shape.size(); ++i) s += (i ? ", " : "") + std::to_string(shape[i]);
  return s + "]";
}

const CheckpointTensor* Checkpoint::find(const std::string& key) const {
  const auto it = tensors.find(key);
  return it == tensors.end() ? nullptr : &it->second;
}

const CheckpointTensor& Checkpoint::at(const std::string& key) const {
  if (const CheckpointTensor* tensor = find(key)) return *tensor;
  throw CheckpointError(Kind::kFormat, "checkpoint '" + path + "' has no tensor '" + key + "'");
}

namespace {

// The loader's errors, each naming the file.
Checkpoint load_naming_the_file(const std::filesystem::path& path, bool with_data) {
  try {
    return Loader(path, with_data).load();
  } catch (const CheckpointError& e) {
    throw CheckpointError(e.kind(), "checkpoint '" + path.string() + "': " + e.what());
  } catch (const std::bad_alloc&) {
    throw CheckpointError(Kind::kFormat, "checkpoint '" + path.string() + "': out of memory");
  }
}

}  // namespace

Checkpoint load_checkpoint(const std::filesystem::path& path) { return load_naming_the_file(path, true); }

Checkpoint read_checkpoint_header(const std::filesystem::path& path) { return load_naming_the_file(path, false); }

}  // namespace neuflow::model
