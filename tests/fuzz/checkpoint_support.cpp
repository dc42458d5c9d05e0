#include "checkpoint_support.hpp"

#include <array>
#include <bit>
#include <cstdint>
#include <set>

#include "fuzz_support.hpp"

namespace neuflow::fuzz {

namespace {

std::uint32_t crc32(std::string_view bytes) {
  static const auto table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1u) != 0 ? 0xedb88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  std::uint32_t crc = 0xffffffffu;
  for (const char ch : bytes) crc = table[(crc ^ static_cast<unsigned char>(ch)) & 0xffu] ^ (crc >> 8);
  return crc ^ 0xffffffffu;
}

void le(std::string& out, std::uint64_t value, int bytes) {
  for (int i = 0; i < bytes; ++i) out += static_cast<char>((value >> (8 * i)) & 0xffu);
}

}  // namespace

std::string pickle_storage_bytes(int index) {
  std::string out;
  for (std::size_t i = 0; i < kPickleStorageBytes / 4; ++i) {
    const float value = static_cast<float>(index) + 0.125f * static_cast<float>(i);
    le(out, std::bit_cast<std::uint32_t>(value), 4);
  }
  return out;
}

std::string stored_zip(const std::vector<std::pair<std::string, std::string>>& entries) {
  std::string out;
  std::string directory;
  for (const auto& [name, data] : entries) {
    const std::uint32_t crc = crc32(data);
    const std::uint64_t offset = out.size();
    // Local file header: version 2.0, no flags, stored, 1980-01-01 00:00.
    le(out, 0x04034b50u, 4);
    le(out, 20, 2);
    le(out, 0, 2);
    le(out, 0, 2);
    le(out, 0, 2);
    le(out, 0x21, 2);
    le(out, crc, 4);
    le(out, data.size(), 4);
    le(out, data.size(), 4);
    le(out, name.size(), 2);
    le(out, 0, 2);
    out += name;
    out += data;
    // Its central-directory record.
    le(directory, 0x02014b50u, 4);
    le(directory, 20, 2);
    le(directory, 20, 2);
    le(directory, 0, 2);
    le(directory, 0, 2);
    le(directory, 0, 2);
    le(directory, 0x21, 2);
    le(directory, crc, 4);
    le(directory, data.size(), 4);
    le(directory, data.size(), 4);
    le(directory, name.size(), 2);
    le(directory, 0, 2);
    le(directory, 0, 2);
    le(directory, 0, 2);
    le(directory, 0, 2);
    le(directory, 0, 4);
    le(directory, offset, 4);
    directory += name;
  }
  const std::uint64_t directory_offset = out.size();
  out += directory;
  // End of central directory.
  le(out, 0x06054b50u, 4);
  le(out, 0, 2);
  le(out, 0, 2);
  le(out, entries.size(), 2);
  le(out, entries.size(), 2);
  le(out, directory.size(), 4);
  le(out, directory_offset, 4);
  le(out, 0, 2);
  return out;
}

std::string checkpoint_around_pickle(std::string pickle) {
  const std::string folder = kPickleFolder;
  std::vector<std::pair<std::string, std::string>> entries;
  entries.emplace_back(folder + "/data.pkl", std::move(pickle));
  for (int i = 0; i < kPickleStorages; ++i) {
    entries.emplace_back(folder + "/data/" + std::to_string(i), pickle_storage_bytes(i));
  }
  entries.emplace_back(folder + "/version", "3\n");
  return stored_zip(entries);
}

void check_checkpoint(const char* harness, const model::Checkpoint& checkpoint) {
  const auto fail = [&](const std::string& what) { invariant_failed(harness, what); };
  if (checkpoint.keys.size() != checkpoint.tensors.size()) {
    fail(std::to_string(checkpoint.keys.size()) + " keys but " + std::to_string(checkpoint.tensors.size()) +
         " tensors");
  }
  const std::set<std::string> unique(checkpoint.keys.begin(), checkpoint.keys.end());
  if (unique.size() != checkpoint.keys.size()) fail("a key listed twice");
  if (checkpoint.wrapper != "model" && checkpoint.wrapper != "state_dict" && checkpoint.wrapper != "bare") {
    fail("wrapper '" + checkpoint.wrapper + "'");
  }
  static const std::set<std::string> dtypes = {"float32", "float16", "bfloat16", "float64", "int64", "int32"};
  for (const auto& key : checkpoint.keys) {
    const model::CheckpointTensor* tensor = checkpoint.find(key);
    if (tensor == nullptr) fail("key '" + key + "' has no tensor");
    for (const auto d : tensor->shape) {
      if (d < 0) fail("tensor '" + key + "' has a negative dimension");
    }
    if (tensor->numel() < 0 || static_cast<std::uint64_t>(tensor->numel()) != tensor->data.size()) {
      fail("tensor '" + key + "' holds " + std::to_string(tensor->data.size()) + " values, numel() is " +
           std::to_string(tensor->numel()));
    }
    if (dtypes.count(tensor->dtype) == 0) fail("tensor '" + key + "' has dtype '" + tensor->dtype + "'");
  }
}

}  // namespace neuflow::fuzz
