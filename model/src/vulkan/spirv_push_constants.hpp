#pragma once
// Reads a SPIR-V module's push-constant block at compile time, so that the build fails when a
// shader's block and the C++ struct recorded with it differ (shader_registry.cpp asserts it for
// every shader). The params headers declare both from one text; this catches what that cannot:
// a shader that declares its own block, or a member whose GLSL type is not 32 bits.
#include <cstddef>
#include <cstdint>
#include <span>

namespace neuflow::model::vulkan::spirv_reflect {

// The SPIR-V opcodes and enumerants read here (SPIR-V specification, section 3).
inline constexpr std::uint32_t kOpTypeInt = 21, kOpTypeFloat = 22, kOpTypeStruct = 30, kOpTypePointer = 32,
                               kOpVariable = 59, kOpMemberDecorate = 72;
inline constexpr std::uint32_t kStorageClassPushConstant = 9, kDecorationOffset = 35;
inline constexpr std::size_t kHeaderWords = 5;

// Calls f(opcode, first operand index, word count) for each instruction; stops when f returns false.
template <typename F>
constexpr void for_each_instruction(std::span<const std::uint32_t> words, F&& f) {
  for (std::size_t i = kHeaderWords; i < words.size();) {
    const std::uint32_t count = words[i] >> 16, opcode = words[i] & 0xffffu;
    if (count == 0 || i + count > words.size()) return;
    if (!f(opcode, i + 1, count)) return;
    i += count;
  }
}

constexpr bool is_32_bit_scalar(std::span<const std::uint32_t> words, std::uint32_t type) {
  bool found = false;
  for_each_instruction(words, [&](std::uint32_t op, std::size_t at, std::uint32_t) {
    if ((op == kOpTypeInt || op == kOpTypeFloat) && words[at] == type) {
      found = words[at + 1] == 32;
      return false;
    }
    return true;
  });
  return found;
}

constexpr bool member_offset_is(std::span<const std::uint32_t> words, std::uint32_t type, std::uint32_t member,
                                std::uint32_t offset) {
  bool found = false;
  for_each_instruction(words, [&](std::uint32_t op, std::size_t at, std::uint32_t count) {
    if (op == kOpMemberDecorate && count >= 5 && words[at] == type && words[at + 1] == member &&
        words[at + 2] == kDecorationOffset) {
      found = words[at + 3] == offset;
      return false;
    }
    return true;
  });
  return found;
}

// The bytes of the module's push-constant block: 0 without one, -1 when it is not a packed
// list of 32-bit scalars (member i at offset 4·i), the only form the params headers declare.
constexpr long push_constant_bytes(std::span<const std::uint32_t> words) {
  std::uint32_t pointer = 0;
  for_each_instruction(words, [&](std::uint32_t op, std::size_t at, std::uint32_t) {
    if (op == kOpVariable && words[at + 2] == kStorageClassPushConstant) {
      pointer = words[at];
      return false;
    }
    return true;
  });
  if (pointer == 0) return 0;
  std::uint32_t block = 0;
  for_each_instruction(words, [&](std::uint32_t op, std::size_t at, std::uint32_t) {
    if (op == kOpTypePointer && words[at] == pointer) {
      block = words[at + 2];
      return false;
    }
    return true;
  });
  long bytes = -1;
  for_each_instruction(words, [&](std::uint32_t op, std::size_t at, std::uint32_t count) {
    if (op != kOpTypeStruct || words[at] != block) return true;
    const std::uint32_t members = count - 2;
    bytes = 4L * members;
    for (std::uint32_t m = 0; m < members; ++m) {
      if (!is_32_bit_scalar(words, words[at + 1 + m]) || !member_offset_is(words, block, m, 4 * m)) bytes = -1;
    }
    return false;
  });
  return bytes;
}

}  // namespace neuflow::model::vulkan::spirv_reflect
