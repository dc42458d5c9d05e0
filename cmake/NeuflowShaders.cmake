# The Vulkan backend's shaders from one list (model/CMakeLists.txt): each neuflow_shader() call
# compiles its shader to SPIR-V in both precisions, and neuflow_shader_registry() then writes the
# registry the C++ side uses (the Shader enum, its count, the SPIR-V tables and each shader's
# push-constant struct), so adding a shader is one line of CMake and one params header.
#
#   neuflow_shader(<name> SOURCE <file.comp> [DEFINES <macro>...] [PARAMS <shader>] [FP16_ONLY]
#                  [TENSOR_CORES] [UNOPTIMIZED])
#     compiles <file.comp> (with -D<macro>...) into <name>.spv.inc and <name>_fp16.spv.inc (-DFP16:
#     tensors stored as float16_t, precision.glsl). Its push constants are declared once, in
#     shaders/params/<name>_params.h as the struct <Name>Params (snake case to camel case), or
#     are those of the shader PARAMS names (a variant of it, recorded in its place).
#     FP16_ONLY: only the fp16 variant exists (its fp32 SPIR-V is empty). TENSOR_CORES: compiled
#     with -DTENSOR_CORES, it needs VK_NV_cooperative_matrix (GpuDevice::tensor_cores); its
#     pipelines are made only there. UNOPTIMIZED: glslc without -O, for the shaders whose
#     arithmetic on cooperative-matrix values crashes Debian 12's spirv-opt (2023.1, in
#     simplify-instructions); the driver optimizes them all the same.
#   neuflow_shader_registry(<target>)
#     writes shader_registry.hpp/.cpp into the shader output folder and adds them to <target>.
#
# Needs: neuflow_shader_command (the compiler's command line), neuflow_shader_compiler (its
# name), shader_dir and shader_out.

set_property(GLOBAL PROPERTY neuflow_shader_names "")
set_property(GLOBAL PROPERTY neuflow_shader_outputs "")

function(neuflow_shader_struct_name name out)
  string(REPLACE "_" ";" parts "${name}")
  set(camel "")
  foreach(part IN LISTS parts)
    string(SUBSTRING "${part}" 0 1 first)
    string(SUBSTRING "${part}" 1 -1 rest)
    string(TOUPPER "${first}" first)
    string(APPEND camel "${first}${rest}")
  endforeach()
  set(${out} "${camel}Params" PARENT_SCOPE)
endfunction()

function(neuflow_shader name)
  cmake_parse_arguments(ARG "FP16_ONLY;TENSOR_CORES;UNOPTIMIZED" "SOURCE;PARAMS" "DEFINES" ${ARGN})
  # A keyword among the macros would end the DEFINES list there and drop the macros after it
  # (TENSOR_CORES once did, and its shaders compiled as their twins): nothing may be left over.
  if(ARG_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "neuflow_shader(${name}): unexpected '${ARG_UNPARSED_ARGUMENTS}' (DEFINES takes macro "
                        "names; TENSOR_CORES is an option that defines its macro itself)")
  endif()
  if(NOT ARG_SOURCE)
    message(FATAL_ERROR "neuflow_shader(${name}): SOURCE <file.comp> is required")
  endif()
  if(NOT ARG_PARAMS)
    set(ARG_PARAMS ${name})
  endif()
  set(params ${shader_dir}/params/${ARG_PARAMS}_params.h)
  if(NOT EXISTS ${params})
    message(FATAL_ERROR "neuflow_shader(${name}): its push constants belong in ${params} (see params/interface.h)")
  endif()
  file(GLOB interface_headers ${shader_dir}/*.glsl ${shader_dir}/params/*.h)
  set(outputs)
  set(variants "" "_fp16")
  if(ARG_FP16_ONLY)
    set(variants "_fp16")
  endif()
  foreach(variant IN LISTS variants)
    set(defines)
    foreach(d IN LISTS ARG_DEFINES)
      list(APPEND defines -D${d})
    endforeach()
    if(variant STREQUAL "_fp16")
      list(APPEND defines -DFP16)
    endif()
    if(ARG_TENSOR_CORES)
      list(APPEND defines -DTENSOR_CORES)
    endif()
    if(ARG_UNOPTIMIZED AND neuflow_shader_compiler STREQUAL "glslc")
      list(APPEND defines -O0)  # after the command's -O, which it overrides
    endif()
    add_custom_command(
      OUTPUT ${shader_out}/${name}${variant}.spv.inc
      COMMAND ${neuflow_shader_command} ${defines} -o ${shader_out}/${name}${variant}.spv.inc
              ${shader_dir}/${ARG_SOURCE}
      DEPENDS ${shader_dir}/${ARG_SOURCE} ${interface_headers}
      COMMENT "${neuflow_shader_compiler} ${ARG_SOURCE} -> ${name}${variant}.spv.inc"
      VERBATIM)
    list(APPEND outputs ${shader_out}/${name}${variant}.spv.inc)
  endforeach()
  set_property(GLOBAL APPEND PROPERTY neuflow_shader_names ${name})
  set_property(GLOBAL PROPERTY neuflow_shader_params_${name} ${ARG_PARAMS})
  set_property(GLOBAL PROPERTY neuflow_shader_fp16_only_${name} ${ARG_FP16_ONLY})
  set_property(GLOBAL PROPERTY neuflow_shader_tensor_cores_${name} ${ARG_TENSOR_CORES})
  set_property(GLOBAL APPEND PROPERTY neuflow_shader_outputs ${outputs})
endfunction()

function(neuflow_shader_registry target)
  get_property(names GLOBAL PROPERTY neuflow_shader_names)
  get_property(outputs GLOBAL PROPERTY neuflow_shader_outputs)
  list(LENGTH names count)
  set(enumerators "")
  set(includes "")
  set(traits "")
  set(tables "")
  set(entries "")
  foreach(name IN LISTS names)
    get_property(params_of GLOBAL PROPERTY neuflow_shader_params_${name})
    get_property(fp16_only GLOBAL PROPERTY neuflow_shader_fp16_only_${name})
    get_property(tensor_cores GLOBAL PROPERTY neuflow_shader_tensor_cores_${name})
    neuflow_shader_struct_name(${params_of} params)
    string(APPEND enumerators "  ${name},\n")
    string(APPEND includes "#include \"params/${params_of}_params.h\"\n")
    string(APPEND traits "template <>\nstruct ShaderParams<Shader::${name}> {\n  using type = ${params};\n};\n")
    string(APPEND tables "constexpr std::uint32_t k_${name}_fp16[] = {\n#include \"${name}_fp16.spv.inc\"\n};\n"
                         "static_assert(sizeof(${params}) <= kMaxPushConstantBytes, \"${name}: push constants over the limit\");\n"
                         "static_assert(spirv_reflect::push_constant_bytes(k_${name}_fp16) == sizeof(${params}),\n"
                         "              \"${name}: the compiled shader's push-constant block is not ${params} (shaders/params/${params_of}_params.h)\");\n")
    if(fp16_only)
      set(fp32_table "{}")
      set(reflected k_${name}_fp16)
    else()
      string(APPEND tables "constexpr std::uint32_t k_${name}[] = {\n#include \"${name}.spv.inc\"\n};\n"
                           "static_assert(spirv_reflect::push_constant_bytes(k_${name}) == sizeof(${params}),\n"
                           "              \"${name}: the compiled shader's push-constant block is not ${params} (shaders/params/${params_of}_params.h)\");\n")
      set(fp32_table k_${name})
      set(reflected k_${name})
    endif()
    if(tensor_cores)
      set(tensor_cores_value true)
    else()
      set(tensor_cores_value false)
    endif()
    # Each shader's reflection is a constant expression of its own: GCC counts its constexpr
    # operations per expression (-fconstexpr-ops-limit), and all of them in the table's one
    # initializer went past GCC 11's limit under -fsanitize=undefined.
    string(APPEND tables "constexpr auto k_${name}_bindings = spirv_reflect::binding_accesses<kShaderBindings>(${reflected});\n")
    string(APPEND entries "    {\"${name}\", ${fp32_table}, k_${name}_fp16, \"${params}\", sizeof(${params}),\n"
                          "     k_${name}_bindings, ${tensor_cores_value}},\n")
  endforeach()
  set(generated "// Generated by cmake/NeuflowShaders.cmake from model/CMakeLists.txt's shader list: do not edit.")
  file(CONFIGURE OUTPUT ${shader_out}/shader_registry.hpp @ONLY CONTENT
"${generated}
#pragma once
#include <cstddef>

${includes}
namespace neuflow::model::vulkan {

enum class Shader {
${enumerators}};
inline constexpr std::size_t kShaderCount = ${count};

// The push-constant struct each shader takes (its params header), so that recording a dispatch
// with another shader's struct does not compile.
template <Shader S>
struct ShaderParams;
${traits}
}  // namespace neuflow::model::vulkan
")
  file(CONFIGURE OUTPUT ${shader_out}/shader_registry.cpp @ONLY CONTENT
"${generated}
#include \"vulkan/shaders.hpp\"
#include \"vulkan/spirv_bindings.hpp\"
#include \"vulkan/spirv_push_constants.hpp\"

namespace neuflow::model::vulkan {

namespace {
// Each .spv.inc is the shader compiler's list of SPIR-V words, comma-separated without braces
// (glslc -mfmt=num, glslangValidator -x).
${tables}
constexpr ShaderInfo kShaders[kShaderCount] = {
${entries}};
}  // namespace

const ShaderInfo& shader_info(Shader shader) { return kShaders[static_cast<std::size_t>(shader)]; }

}  // namespace neuflow::model::vulkan
")
  add_custom_target(neuflow_shaders DEPENDS ${outputs})
  target_sources(${target} PRIVATE ${shader_out}/shader_registry.cpp)
  target_include_directories(${target} PUBLIC $<BUILD_INTERFACE:${shader_out}> $<BUILD_INTERFACE:${shader_dir}>)
  add_dependencies(${target} neuflow_shaders)
endfunction()
