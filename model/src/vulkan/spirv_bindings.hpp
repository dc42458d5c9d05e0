#pragma once
// Which of a shader's storage-buffer bindings it reads and which it writes, read from its
// SPIR-V (`readonly` and `writeonly` become NonWritable and NonReadable), so the recorder's
// barriers follow the shaders themselves rather than a table that could drift from them.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "vulkan/spirv_push_constants.hpp"

namespace neuflow::model::vulkan::spirv_reflect {

inline constexpr std::uint32_t kOpDecorate = 71;
inline constexpr std::uint32_t kDecorationBinding = 33, kDecorationNonWritable = 24, kDecorationNonReadable = 25;

struct BindingAccess {
  bool reads = false, writes = false;  // both false: the shader does not declare the binding
};

// Whether `target` (a variable or a block type's member 0) carries `decoration`.
constexpr bool decorated(std::span<const std::uint32_t> words, std::uint32_t target, std::uint32_t decoration) {
  bool found = false;
  for_each_instruction(words, [&](std::uint32_t op, std::size_t at, std::uint32_t count) {
    if ((op == kOpDecorate && count >= 3 && words[at] == target && words[at + 1] == decoration) ||
        (op == kOpMemberDecorate && count >= 4 && words[at] == target && words[at + 2] == decoration)) {
      found = true;
      return false;
    }
    return true;
  });
  return found;
}

// The block type a variable points to (0: not found).
constexpr std::uint32_t pointee_of_variable(std::span<const std::uint32_t> words, std::uint32_t variable) {
  std::uint32_t pointer = 0, pointee = 0;
  for_each_instruction(words, [&](std::uint32_t op, std::size_t at, std::uint32_t) {
    if (op == kOpVariable && words[at + 1] == variable) pointer = words[at];
    return pointer == 0;
  });
  for_each_instruction(words, [&](std::uint32_t op, std::size_t at, std::uint32_t) {
    if (op == kOpTypePointer && words[at] == pointer) pointee = words[at + 2];
    return pointee == 0;
  });
  return pointee;
}

template <std::size_t N>
constexpr std::array<BindingAccess, N> binding_accesses(std::span<const std::uint32_t> words) {
  std::array<BindingAccess, N> result{};
  for_each_instruction(words, [&](std::uint32_t op, std::size_t at, std::uint32_t count) {
    if (op != kOpDecorate || count < 4 || words[at + 1] != kDecorationBinding || words[at + 2] >= N) return true;
    const std::uint32_t variable = words[at], block = pointee_of_variable(words, variable);
    const bool read_only =
        decorated(words, variable, kDecorationNonWritable) || decorated(words, block, kDecorationNonWritable);
    const bool write_only =
        decorated(words, variable, kDecorationNonReadable) || decorated(words, block, kDecorationNonReadable);
    result[words[at + 2]] = {!write_only, !read_only};
    return true;
  });
  return result;
}

}  // namespace neuflow::model::vulkan::spirv_reflect
