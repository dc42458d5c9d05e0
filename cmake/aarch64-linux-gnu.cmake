# Cross-compiles for 64-bit Arm Linux (a Jetson's aarch64, JetPack 6) with Debian's cross
# toolchain (g++-aarch64-linux-gnu, from crossbuild-essential-arm64):
#
#   cmake -S . -B build/arm64 -G Ninja --toolchain cmake/aarch64-linux-gnu.cmake \
#         -DNEUFLOW_ARM64_SYSROOT=/path/to/arm64-root
#
# NEUFLOW_ARM64_SYSROOT (or the variable of that name in the environment) is a folder holding an
# arm64 Debian's /usr: the -dev packages' headers, libraries and pkg-config files
# (scripts/check-arm64.sh makes one). Without it, the arm64 packages are expected installed on
# the host through multiarch (`dpkg --add-architecture arm64`, `apt install libfoo-dev:arm64`).
#
# The test programs run under qemu-user: ctest and gtest's test discovery go through
# CMAKE_CROSSCOMPILING_EMULATOR; what the tests themselves start (the CLI, gst-inspect-1.0 of
# the arm64 root) runs through binfmt_misc with QEMU_LD_PREFIX pointing at the root.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_LIBRARY_ARCHITECTURE aarch64-linux-gnu)

set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)

if(NOT NEUFLOW_ARM64_SYSROOT AND DEFINED ENV{NEUFLOW_ARM64_SYSROOT})
  set(NEUFLOW_ARM64_SYSROOT "$ENV{NEUFLOW_ARM64_SYSROOT}")
endif()
# try_compile's projects read this file again: hand them the root too.
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES NEUFLOW_ARM64_SYSROOT)

find_program(NEUFLOW_QEMU_AARCH64 NAMES qemu-aarch64-static qemu-aarch64)

if(NEUFLOW_ARM64_SYSROOT)
  if(NOT EXISTS "${NEUFLOW_ARM64_SYSROOT}/usr/lib/aarch64-linux-gnu")
    message(FATAL_ERROR "NEUFLOW_ARM64_SYSROOT=${NEUFLOW_ARM64_SYSROOT} has no "
                        "usr/lib/aarch64-linux-gnu: it is not an arm64 Debian root (make one "
                        "with scripts/check-arm64.sh --sysroot-only)")
  endif()
  set(CMAKE_SYSROOT "${NEUFLOW_ARM64_SYSROOT}")
  set(CMAKE_FIND_ROOT_PATH "${NEUFLOW_ARM64_SYSROOT}")
  # The sysroot's pkg-config files, with their paths moved into it.
  set(ENV{PKG_CONFIG_SYSROOT_DIR} "${NEUFLOW_ARM64_SYSROOT}")
  set(ENV{PKG_CONFIG_LIBDIR}
      "${NEUFLOW_ARM64_SYSROOT}/usr/lib/aarch64-linux-gnu/pkgconfig:${NEUFLOW_ARM64_SYSROOT}/usr/share/pkgconfig")
  # The root's libraries are found at link time through their sonames, as on the device.
  set(CMAKE_EXE_LINKER_FLAGS_INIT
      "-Wl,-rpath-link,${NEUFLOW_ARM64_SYSROOT}/usr/lib/aarch64-linux-gnu -Wl,-rpath-link,${NEUFLOW_ARM64_SYSROOT}/lib/aarch64-linux-gnu")
  set(CMAKE_SHARED_LINKER_FLAGS_INIT "${CMAKE_EXE_LINKER_FLAGS_INIT}")
  set(CMAKE_MODULE_LINKER_FLAGS_INIT "${CMAKE_EXE_LINKER_FLAGS_INIT}")
  if(NEUFLOW_QEMU_AARCH64)
    set(CMAKE_CROSSCOMPILING_EMULATOR "${NEUFLOW_QEMU_AARCH64};-L;${NEUFLOW_ARM64_SYSROOT}")
  endif()
else()
  set(ENV{PKG_CONFIG_LIBDIR} "/usr/lib/aarch64-linux-gnu/pkgconfig:/usr/share/pkgconfig")
  if(NEUFLOW_QEMU_AARCH64)
    set(CMAKE_CROSSCOMPILING_EMULATOR "${NEUFLOW_QEMU_AARCH64};-L;/usr/aarch64-linux-gnu")
  endif()
endif()

# Programs run at build time (glslc, python3) are the host's; libraries, headers and CMake
# packages are the target's.
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
