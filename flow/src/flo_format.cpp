#include "neuflow/flow/flo_format.hpp"

#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <span>
#include <string>
#include <vector>

#include "binary.hpp"
#include "field_check.hpp"
#include "file_io.hpp"
#include "neuflow/flow/errors.hpp"
#include "neuflow/flow/limits.hpp"

namespace neuflow::flow {

namespace {

using Kind = FlowFileError::Kind;
constexpr std::size_t kHeaderBytes = 12;

bool known(float x) { return std::isfinite(x) && std::fabs(x) <= kFloUnknownThreshold; }

// Unknown pixels become invalid with a zero placeholder; the mask is created on the first one.
void mark_unknown_pixels(FlowField& field) {
  const std::size_t n = field.pixel_count();
  for (std::size_t i = 0; i < n; ++i) {
    float& u = field.uv[2 * i];
    float& v = field.uv[2 * i + 1];
    if (known(u) && known(v)) continue;
    if (field.valid.empty()) field.valid.assign(n, 1);
    field.valid[i] = 0;
    u = 0.f;
    v = 0.f;
  }
}

}  // namespace

FlowField read_flo(const std::filesystem::path& path) {
  detail::BinaryInput in(path);
  std::array<std::byte, kHeaderBytes> header{};
  if (in.size() < kHeaderBytes) {
    throw FlowFileError(Kind::malformed, path,
                        "truncated: " + std::to_string(in.size()) + " bytes, shorter than the 12-byte .flo header");
  }
  in.read(header, "header");
  if (std::memcmp(header.data(), "PIEH", 4) != 0) {
    throw FlowFileError(Kind::malformed, path,
                        "not a Middlebury .flo file: wrong magic (expected \"PIEH\", i.e. float "
                        "202021.25)");
  }
  const std::int64_t width = detail::load_le_i32(header.data() + 4);
  const std::int64_t height = detail::load_le_i32(header.data() + 8);
  if (!flow_size_acceptable(width, height)) {
    throw FlowFileError(Kind::malformed, path,
                        "implausible size " + std::to_string(width) + "x" + std::to_string(height) +
                            " in the header (accepted: 1.." + std::to_string(kMaxFlowSide) + " per side, at most " +
                            std::to_string(kMaxFlowPixels) + " pixels)");
  }
  // Check against the file size before allocating what the header claims.
  const std::uint64_t expected = kHeaderBytes + 8 * static_cast<std::uint64_t>(width * height);
  if (in.size() != expected) {
    throw FlowFileError(Kind::malformed, path,
                        std::string(in.size() < expected ? "truncated" : "trailing data") + ": the header says " +
                            std::to_string(width) + "x" + std::to_string(height) + ", which needs " +
                            std::to_string(expected) + " bytes, but the file is " + std::to_string(in.size()) +
                            " bytes");
  }

  FlowField field(static_cast<int>(width), static_cast<int>(height));
  in.read(std::as_writable_bytes(std::span(field.uv)), "flow data");
  if constexpr (std::endian::native == std::endian::big) {
    for (float& x : field.uv) x = detail::load_le_f32(reinterpret_cast<const std::byte*>(&x));
  }
  mark_unknown_pixels(field);
  return field;
}

void write_flo(const FlowField& field, const std::filesystem::path& path) {
  detail::check_field(field, "write_flo " + path.string());
  const std::size_t n = field.pixel_count();
  std::vector<std::byte> bytes(kHeaderBytes + 8 * n);
  std::memcpy(bytes.data(), "PIEH", 4);
  detail::store_le_i32(bytes.data() + 4, field.width);
  detail::store_le_i32(bytes.data() + 8, field.height);
  std::byte* out = bytes.data() + kHeaderBytes;
  for (std::size_t i = 0; i < n; ++i, out += 8) {
    float u = field.uv[2 * i];
    float v = field.uv[2 * i + 1];
    const bool valid = (field.valid.empty() || field.valid[i] != 0) && std::isfinite(u) && std::isfinite(v);
    if (!valid) u = v = kFloUnknownValue;
    detail::store_le_f32(out, u);
    detail::store_le_f32(out + 4, v);
  }
  detail::write_file_atomically(path, bytes);
}

}  // namespace neuflow::flow
