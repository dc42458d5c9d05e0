# Cross-compiling for 64-bit Arm Linux (Jetson, Raspberry Pi 4/5) on a Debian amd64 host with
# multiarch: crossbuild-essential-arm64 and the :arm64 variants of the -dev packages, whose
# libraries land in /usr/lib/aarch64-linux-gnu beside the host's (scripts/ci-arm64.sh).
#   cmake -S . -B build/arm64 -G Ninja -DCMAKE_TOOLCHAIN_FILE=cmake/toolchain-aarch64-linux-gnu.cmake
# Test programs run under qemu-user (CMAKE_CROSSCOMPILING_EMULATOR), so `ctest` works as usual.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)
set(CMAKE_LIBRARY_ARCHITECTURE aarch64-linux-gnu)

# Headers are shared between architectures in /usr/include; libraries and pkg-config files
# are per architecture. Host programs (glslc, python3) still come from the host.
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(ENV{PKG_CONFIG_LIBDIR} "/usr/lib/aarch64-linux-gnu/pkgconfig:/usr/share/pkgconfig")
set(ENV{PKG_CONFIG_PATH} "")

# The arm64 dynamic loader and libraries that multiarch installed live under /, so qemu needs
# no separate sysroot; QEMU_LD_PREFIX is only for a sysroot elsewhere.
find_program(NEUFLOW_QEMU_AARCH64 NAMES qemu-aarch64-static qemu-aarch64)
if(NEUFLOW_QEMU_AARCH64)
  set(CMAKE_CROSSCOMPILING_EMULATOR "${NEUFLOW_QEMU_AARCH64}")
endif()
