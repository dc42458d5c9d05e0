#include "checkpoint_builder.hpp"

#include <zip.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <random>
#include <stdexcept>

#include "neuflow/model/architecture.hpp"

namespace neuflow::test {

namespace {

void append_le(std::string& out, uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) out += static_cast<char>((v >> (8 * i)) & 0xff);
}

std::vector<int64_t> contiguous_strides(const std::vector<int64_t>& size) {
  std::vector<int64_t> stride(size.size());
  int64_t s = 1;
  for (std::size_t i = size.size(); i-- > 0;) {
    stride[i] = s;
    s *= size[i];
  }
  return stride;
}

}  // namespace

PickleWriter& PickleWriter::proto(int protocol) {
  bytes_ += static_cast<char>(0x80);
  bytes_ += static_cast<char>(protocol);
  return *this;
}
PickleWriter& PickleWriter::frame(uint64_t length) {
  bytes_ += static_cast<char>(0x95);
  append_le(bytes_, length, 8);
  return *this;
}
PickleWriter& PickleWriter::raw(std::string_view bytes) {
  bytes_ += bytes;
  return *this;
}
PickleWriter& PickleWriter::op(unsigned char opcode) {
  bytes_ += static_cast<char>(opcode);
  return *this;
}
PickleWriter& PickleWriter::str(std::string_view s) {
  bytes_ += 'X';
  append_le(bytes_, s.size(), 4);
  bytes_ += s;
  return *this;
}
PickleWriter& PickleWriter::short_str(std::string_view s) {
  bytes_ += static_cast<char>(0x8c);
  append_le(bytes_, s.size(), 1);
  bytes_ += s;
  return *this;
}
PickleWriter& PickleWriter::integer(int64_t v) {
  if (v >= 0 && v < 256) {
    bytes_ += 'K';
    append_le(bytes_, static_cast<uint64_t>(v), 1);
  } else if (v >= 0 && v < 65536) {
    bytes_ += 'M';
    append_le(bytes_, static_cast<uint64_t>(v), 2);
  } else if (v >= INT32_MIN && v <= INT32_MAX) {
    bytes_ += 'J';
    append_le(bytes_, static_cast<uint64_t>(v), 4);
  } else {
    // LONG1 with the shortest two's-complement encoding.
    int n = 8;
    while (n > 1) {
      const int64_t lo = -(int64_t{1} << (8 * (n - 1) - 1));
      const int64_t hi = (int64_t{1} << (8 * (n - 1) - 1)) - 1;
      if (v < lo || v > hi) break;
      --n;
    }
    bytes_ += static_cast<char>(0x8a);
    bytes_ += static_cast<char>(n);
    append_le(bytes_, static_cast<uint64_t>(v), n);
  }
  return *this;
}
PickleWriter& PickleWriter::real(double v) {
  bytes_ += 'G';
  const auto bits = std::bit_cast<uint64_t>(v);
  for (int i = 7; i >= 0; --i) bytes_ += static_cast<char>((bits >> (8 * i)) & 0xff);
  return *this;
}
PickleWriter& PickleWriter::global(std::string_view module, std::string_view name) {
  bytes_ += 'c';
  bytes_ += module;
  bytes_ += '\n';
  bytes_ += name;
  bytes_ += '\n';
  return *this;
}
PickleWriter& PickleWriter::stack_global(std::string_view module, std::string_view name) {
  short_str(module);
  short_str(name);
  return op(0x93);
}
PickleWriter& PickleWriter::put(uint32_t index) {
  if (index < 256) {
    bytes_ += 'q';
    append_le(bytes_, index, 1);
  } else {
    bytes_ += 'r';
    append_le(bytes_, index, 4);
  }
  return *this;
}
PickleWriter& PickleWriter::get(uint32_t index) {
  if (index < 256) {
    bytes_ += 'h';
    append_le(bytes_, index, 1);
  } else {
    bytes_ += 'j';
    append_le(bytes_, index, 4);
  }
  return *this;
}

void emit_tensor(PickleWriter& w, const FakeTensor& t) {
  if (t.as_parameter) w.global("torch._utils", "_rebuild_parameter").mark();
  w.global("torch._utils", "_rebuild_tensor_v2");
  w.mark();
  w.mark().str("storage").global("torch", t.storage_type).str(t.storage_key).str("cpu");
  w.integer(t.storage_numel).tuple().binpersid();
  w.integer(t.offset);
  w.mark();
  for (const int64_t s : t.size) w.integer(s);
  w.tuple();
  w.mark();
  for (const int64_t s : t.stride.empty() ? contiguous_strides(t.size) : t.stride) w.integer(s);
  w.tuple();
  w.boolean(false);
  w.global("collections", "OrderedDict").empty_tuple().reduce();
  w.tuple().reduce();
  if (t.as_parameter) {
    w.boolean(true).global("collections", "OrderedDict").empty_tuple().reduce();
    w.tuple().reduce();
  }
}

std::string state_dict_pickle(const std::vector<FakeTensor>& tensors, Wrapper wrapper) {
  PickleWriter w;
  w.proto(2);
  const bool wrapped = wrapper != Wrapper::kBare;
  if (wrapped) {
    w.empty_dict().put(0);
    w.str(wrapper == Wrapper::kStateDict ? "state_dict" : "model");
  }
  if (wrapper == Wrapper::kOrderedDictWithMetadata) {
    w.global("collections", "OrderedDict").empty_tuple().reduce();
  } else {
    w.empty_dict();
  }
  w.put(1).mark();
  for (const auto& t : tensors) {
    w.str(t.name);
    emit_tensor(w, t);
  }
  w.setitems();
  if (wrapper == Wrapper::kOrderedDictWithMetadata) {
    // The `_metadata` attribute torch attaches to state dicts, restored through BUILD.
    w.empty_dict().str("_metadata").global("collections", "OrderedDict").empty_tuple().reduce();
    w.mark();
    for (const char* module : {"", "backbone", "backbone.block_8_1"}) {
      w.str(module).empty_dict().str("version").integer(1).setitem();
    }
    w.setitems().setitem().build();
  }
  if (wrapped) w.setitem();
  if (wrapper == Wrapper::kModelWithExtras) {
    w.str("epoch").integer(17).setitem();
    w.str("lr").real(1e-4).setitem();
    w.str("optimizer").none().setitem();
    w.str("best").boolean(true).setitem();
    w.str("history").empty_list().mark().integer(1).integer(-70000).integer(int64_t{1} << 40);
    w.appends().integer(5).append().setitem();
  }
  w.stop();
  return w.bytes();
}

void write_zip(const std::filesystem::path& path, const std::vector<ZipEntry>& entries) {
  int error = 0;
  zip_t* archive = zip_open(path.c_str(), ZIP_CREATE | ZIP_TRUNCATE, &error);
  if (archive == nullptr) throw std::runtime_error("zip_open failed for " + path.string());
  for (const auto& entry : entries) {
    zip_source_t* source = zip_source_buffer(archive, entry.data.data(), entry.data.size(), 0);
    if (source == nullptr) throw std::runtime_error("zip_source_buffer failed");
    const zip_int64_t index = zip_file_add(archive, entry.name.c_str(), source, ZIP_FL_OVERWRITE);
    if (index < 0) {
      zip_source_free(source);
      throw std::runtime_error("zip_file_add failed for " + entry.name);
    }
    zip_set_file_compression(archive, static_cast<zip_uint64_t>(index), entry.compress ? ZIP_CM_DEFLATE : ZIP_CM_STORE,
                             0);
  }
  if (zip_close(archive) != 0) {
    const std::string message = zip_strerror(archive);
    zip_discard(archive);
    throw std::runtime_error("zip_close failed: " + message);
  }
}

std::string le_floats(const std::vector<float>& values) {
  std::string out;
  for (const float v : values) append_le(out, std::bit_cast<uint32_t>(v), 4);
  return out;
}
std::string le_u16(const std::vector<uint16_t>& values) {
  std::string out;
  for (const uint16_t v : values) append_le(out, v, 2);
  return out;
}
std::string le_doubles(const std::vector<double>& values) {
  std::string out;
  for (const double v : values) append_le(out, std::bit_cast<uint64_t>(v), 8);
  return out;
}
std::string le_i64(const std::vector<int64_t>& values) {
  std::string out;
  for (const int64_t v : values) append_le(out, static_cast<uint64_t>(v), 8);
  return out;
}
std::string le_i32(const std::vector<int32_t>& values) {
  std::string out;
  for (const int32_t v : values) append_le(out, static_cast<uint32_t>(v), 4);
  return out;
}

std::string FakeCheckpoint::pickle() const {
  return pickle_override ? *pickle_override : state_dict_pickle(tensors, wrapper);
}

std::vector<ZipEntry> FakeCheckpoint::entries() const {
  std::vector<ZipEntry> out;
  out.push_back({folder + "/data.pkl", pickle()});
  for (const auto& [key, bytes] : storages) out.push_back({folder + "/data/" + key, bytes});
  out.push_back({folder + "/version", "3\n"});
  return out;
}

void FakeCheckpoint::write(const std::filesystem::path& path) const { write_zip(path, entries()); }

FakeCheckpoint fake_neuflow_checkpoint() {
  FakeCheckpoint ckpt;
  int64_t largest = 0;
  for (const auto& spec : model::neuflow_v2_parameters()) largest = std::max(largest, spec.numel());
  std::vector<float> ramp(static_cast<std::size_t>(largest));
  for (std::size_t i = 0; i < ramp.size(); ++i) ramp[i] = static_cast<float>(i % 1000) * 1e-3f;
  ckpt.storages.emplace_back("0", le_floats(ramp));
  ckpt.storages.emplace_back("1", le_i64({42}));
  for (const auto& spec : model::neuflow_v2_parameters()) {
    FakeTensor t;
    t.name = spec.name;
    t.size = spec.shape;
    if (spec.kind == model::ParameterKind::kBatchCounter) {
      t.storage_type = "LongStorage";
      t.storage_key = "1";
      t.storage_numel = 1;
    } else {
      t.storage_key = "0";
      t.storage_numel = largest;
    }
    ckpt.tensors.push_back(std::move(t));
  }
  return ckpt;
}

FakeCheckpoint random_neuflow_checkpoint(std::uint32_t seed) {
  const auto& specs = model::neuflow_v2_parameters();
  // A weight's fan-in, by its layer's name, for the layer's bias too.
  std::map<std::string, int64_t> fan_in;
  for (const auto& spec : specs) {
    if (spec.name.ends_with(".weight") && spec.shape.size() >= 2) {
      int64_t fan = 1;
      for (std::size_t d = 1; d < spec.shape.size(); ++d) fan *= spec.shape[d];
      fan_in[spec.name.substr(0, spec.name.size() - 7)] = fan;
    }
  }
  std::mt19937 random(seed);
  FakeCheckpoint ckpt;
  for (const auto& spec : specs) {
    FakeTensor t;
    t.name = spec.name;
    t.size = spec.shape;
    t.storage_key = std::to_string(ckpt.storages.size());
    t.storage_numel = spec.numel();
    if (spec.kind == model::ParameterKind::kBatchCounter) {
      t.storage_type = "LongStorage";
      ckpt.storages.emplace_back(t.storage_key, le_i64({0}));
      ckpt.tensors.push_back(std::move(t));
      continue;
    }
    const std::string layer = spec.name.substr(0, spec.name.rfind('.'));
    const auto fan = fan_in.find(layer);
    std::vector<float> values(static_cast<std::size_t>(spec.numel()));
    if (fan != fan_in.end()) {  // a convolution's or linear layer's weight or bias
      const float bound = 1.f / std::sqrt(static_cast<float>(fan->second));
      std::uniform_real_distribution<float> uniform(-bound, bound);
      for (float& v : values) v = uniform(random);
    } else {  // a norm's scale and running variance 1, its shift and running mean 0
      const bool one = spec.name.ends_with(".weight") || spec.name.ends_with(".running_var");
      std::fill(values.begin(), values.end(), one ? 1.f : 0.f);
    }
    ckpt.storages.emplace_back(t.storage_key, le_floats(values));
    ckpt.tensors.push_back(std::move(t));
  }
  return ckpt;
}

std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path.string());
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_file(const std::filesystem::path& path, std::string_view bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

}  // namespace neuflow::test
