# Every target of ours links neuflow::options; third-party code never sees these flags.
add_library(neuflow_options INTERFACE)
add_library(neuflow::options ALIAS neuflow_options)

target_compile_options(neuflow_options INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Wcast-align
  # GLib/GStreamer type macros (G_DEFINE_TYPE, GST_*_CAST) expand to C casts: targets built on
  # them set the property NEUFLOW_GLIB_MACROS.
  $<$<NOT:$<BOOL:$<TARGET_PROPERTY:NEUFLOW_GLIB_MACROS>>>:-Wold-style-cast>
  -Woverloaded-virtual -Wformat=2 -Wimplicit-fallthrough
  # GCC 12 reports -Wrestrict inside libstdc++'s own std::string code at -O3 (GCC bug 105329).
  $<$<CXX_COMPILER_ID:GNU>:-Wno-restrict>
  # GCC 12 warns on designated initializers that leave members at their defaults (bug 96868).
  -Wno-missing-field-initializers
  $<$<BOOL:${NEUFLOW_WERROR}>:-Werror>)
# Not enabled: -Wnull-dereference (false positives on GCC 12 at -O3) and -Wdouble-promotion
# (numeric code here deliberately accumulates floats in double).

# AVX2+FMA are the floor of the deployment targets we measure on; the Jetson (aarch64) build
# takes the compiler's default there. NEUFLOW_X86_AVX2=OFF builds x86 for its baseline (SSE2),
# which proves the portable code paths (the Winograd transforms and product kernel) on x86;
# code that needs AVX2 or AVX-512 is chosen at run time either way.
option(NEUFLOW_X86_AVX2 "Compile for AVX2+FMA on x86-64 (OFF: the x86-64 baseline)" ON)
if(CMAKE_SYSTEM_PROCESSOR MATCHES "x86_64|AMD64" AND NEUFLOW_X86_AVX2)
  target_compile_options(neuflow_options INTERFACE -mavx2 -mfma -mf16c)
endif()

if(NEUFLOW_SANITIZE)
  # GCC 12's -Wmaybe-uninitialized fires on libstdc++'s own <regex> internals once ASan
  # instruments them (known false positives); the release build keeps the warning.
  target_compile_options(neuflow_options INTERFACE
    -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined
    -Wno-maybe-uninitialized)
  target_link_options(neuflow_options INTERFACE -fsanitize=address,undefined)
endif()

if(NEUFLOW_FUZZ)
  # Coverage feedback for libFuzzer and the sanitizers on everything of ours; the harness
  # executables add -fsanitize=fuzzer themselves (tests/fuzz/CMakeLists.txt). No NDEBUG in the
  # fuzz preset, so assertions (ours and toml++'s) stay live.
  target_compile_options(neuflow_options INTERFACE
    -fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer
    -fno-sanitize-recover=undefined)
  target_link_options(neuflow_options INTERFACE -fsanitize=address,undefined)
endif()
