#!/usr/bin/env bash
# Compiles the inference core (model/, flow/ and the libraries they are made of) with g++-11,
# JetPack 6's compiler, warnings as errors. Usage: bash scripts/check-gcc11.sh [BUILD_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build/gcc11}
if ! command -v g++-11 >/dev/null; then
  echo "check-gcc11: g++-11 is not installed (Debian: apt install g++-11)" >&2
  exit 1
fi
cmake -S . -B "$build" -G Ninja -DCMAKE_C_COMPILER=gcc-11 -DCMAKE_CXX_COMPILER=g++-11 \
  -DCMAKE_BUILD_TYPE=Release -DNEUFLOW_WERROR=ON -DNEUFLOW_BUILD_TESTS=OFF -DNEUFLOW_BUILD_BENCHMARKS=OFF \
  -DNEUFLOW_BUILD_PLUGIN=OFF >/dev/null
cmake --build "$build" --target neuflow_flow neuflow_session_settings neuflow_checkpoint neuflow_model
echo "check-gcc11: model/ and flow/ compile with $(g++-11 --version | head -1)"
