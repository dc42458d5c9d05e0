#!/usr/bin/env bash
# Runs the core benchmark one size per process, so each size's peak RSS is its own, with the
# sgemm peak measured in the same process before it. Usage: bench/run-core.sh [BUILD_DIR] [THREADS]
set -euo pipefail
build=${1:-build/release}
threads=${2:-2}
for size in 320x256 512x384 768x432 1024x448 1920x1088; do
  "$build/bench/neuflow-bench-core" --threads "$threads" --sizes "$size" \
    --benchmark_filter='sgemm|pair|stream' --benchmark_counters_tabular=true
done
