#pragma once
// Little-endian encoding of the binary formats (internal). The formats are little-endian on
// every platform; these keep the readers correct on big-endian hosts too.
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace neuflow::flow::detail {

inline std::uint32_t load_le_u32(const std::byte* p) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | std::to_integer<std::uint32_t>(p[i]);
  return v;
}
inline std::uint16_t load_le_u16(const std::byte* p) {
  return static_cast<std::uint16_t>(std::to_integer<unsigned>(p[0]) | (std::to_integer<unsigned>(p[1]) << 8));
}
inline std::int32_t load_le_i32(const std::byte* p) { return std::bit_cast<std::int32_t>(load_le_u32(p)); }
inline float load_le_f32(const std::byte* p) { return std::bit_cast<float>(load_le_u32(p)); }

inline void store_le_u32(std::byte* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::byte>((v >> (8 * i)) & 0xffu);
}
inline void store_le_u16(std::byte* p, std::uint16_t v) {
  p[0] = static_cast<std::byte>(v & 0xffu);
  p[1] = static_cast<std::byte>(v >> 8);
}
inline void store_le_i32(std::byte* p, std::int32_t v) { store_le_u32(p, std::bit_cast<std::uint32_t>(v)); }
inline void store_le_f32(std::byte* p, float v) { store_le_u32(p, std::bit_cast<std::uint32_t>(v)); }

}  // namespace neuflow::flow::detail
