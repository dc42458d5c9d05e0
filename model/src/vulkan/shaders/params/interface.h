// The one declaration of what the host and a shader share: each shader's push constants and the
// codes they carry. Every header in this folder is included by its shader's GLSL (through
// GL_GOOGLE_include_directive) and by the C++ that records the shader, so the two cannot drift;
// the build then checks each compiled shader's push-constant block against sizeof of the C++
// struct (spirv_push_constants.hpp, asserted in the generated shader_registry.cpp).
//
// Members are 32-bit scalars only: std430 (push constants) and C++ then lay them out alike,
// every member at 4 × its index, which the check asserts.
#ifndef NEUFLOW_SHADER_INTERFACE_H
#define NEUFLOW_SHADER_INTERFACE_H

#ifdef __cplusplus
#include <cstdint>
#define NEUFLOW_PUSH_CONSTANTS(Name) \
  namespace neuflow::model::vulkan {   \
  struct Name {
#define NEUFLOW_PUSH_CONSTANTS_END \
  };                               \
  }
#define NEUFLOW_SHADER_CONST(name, value) \
  namespace neuflow::model::vulkan {      \
  inline constexpr int name = value;      \
  }
#else
#define NEUFLOW_PUSH_CONSTANTS(Name) layout(push_constant) uniform Name {
#define NEUFLOW_PUSH_CONSTANTS_END \
  }                                \
  p;
#define NEUFLOW_SHADER_CONST(name, value) const int name = value;
#endif

#endif
