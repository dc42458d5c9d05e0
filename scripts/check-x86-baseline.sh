#!/usr/bin/env bash
# Builds the core for the x86-64 baseline (no -mavx2 -mfma, as an aarch64 build has no AVX
# either) and runs the Winograd and convolution tests there: the portable transforms and
# product kernel must compile and give the same results. Usage: bash scripts/check-x86-baseline.sh [BUILD_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build/x86-baseline}
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DNEUFLOW_WERROR=ON -DNEUFLOW_X86_AVX2=OFF \
  -DNEUFLOW_BUILD_BENCHMARKS=OFF -DNEUFLOW_BUILD_PLUGIN=OFF >/dev/null
cmake --build "$build" --target winograd_conv_tests network_kernel_tests
"$build/tests/model/winograd_conv_tests"
"$build/tests/model/network_kernel_tests"
echo "check-x86-baseline: the Winograd and convolution tests pass without -mavx2 -mfma"
