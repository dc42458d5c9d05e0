#!/usr/bin/env bash
# Builds the inference core as a Jetson's toolchain would: with g++-11 (JetPack 6's compiler),
# warnings as errors, and without x86's vector extensions (no -mavx2 -mfma: the x86-64
# baseline, which like aarch64 takes the portable Winograd transforms and product kernel).
# Then runs the Winograd and convolution tests on that build: the portable code must give the
# same results. One build checks both, to keep CI short.
# Usage: bash scripts/check-portable-core.sh [BUILD_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build/portable-core}
if ! command -v g++-11 >/dev/null; then
  echo "check-portable-core: g++-11 is not installed (Debian: apt install g++-11)" >&2
  exit 1
fi
cmake -S . -B "$build" -G Ninja -DCMAKE_C_COMPILER=gcc-11 -DCMAKE_CXX_COMPILER=g++-11 \
  -DCMAKE_BUILD_TYPE=Release -DNEUFLOW_WERROR=ON -DNEUFLOW_X86_AVX2=OFF \
  -DNEUFLOW_BUILD_BENCHMARKS=OFF -DNEUFLOW_BUILD_PLUGIN=OFF -DNEUFLOW_BUILD_PYTHON=OFF >/dev/null
cmake --build "$build" --target neuflow_flow neuflow_session_settings neuflow_checkpoint neuflow_model \
  winograd_conv_tests network_kernel_tests
"$build/tests/model/winograd_conv_tests"
"$build/tests/model/network_kernel_tests"
echo "check-portable-core: model/ and flow/ compile with $(g++-11 --version | head -1) for the" \
     "x86-64 baseline, and the Winograd and convolution tests pass there"
