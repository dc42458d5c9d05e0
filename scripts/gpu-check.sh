#!/usr/bin/env bash
# The GPU checks of the Vulkan backend, for a machine with a GPU that has none of this project's
# build dependencies (the lent GPU machine: its own OS, the NVIDIA driver and nothing else).
#
#   bash scripts/gpu-check.sh pack [DIR]          here: build neuflow-gpu-check (release preset)
#                                                 and pack it, every library it loads (glibc and
#                                                 its loader included) and Debian's Vulkan loader
#                                                 into DIR/bundle.tar.xz (DIR: .gpu-check, which
#                                                 git ignores, so the device tool's carry takes it)
#   bash scripts/gpu-check.sh run [DIR] [ARGS]    there: unpack and run it, within 8 minutes.
#                                                 ARGS go to neuflow-gpu-check (default: parity
#                                                 at 768x432, times at 768x432 and 1024x448)
#
# What it runs (tests/model/gpu_check.cpp): the GPU's fp32 flow against the CPU's, fp16 against
# fp32, and on a GPU with VK_NV_cooperative_matrix the tensor-core products against fp32 and
# against their emulated twin; then one table of times (streamed frames pipelined, pairs, the
# GPU's own time of a frame) and counts per size, precision and product kernels. The table
# goes to stdout and, where $OUT is set (the device tool's output folder), to $OUT/gpu-check.txt.
set -euo pipefail
mode=${1:-}
dir=${2:-.gpu-check}
say() { echo "gpu-check: $*"; }

case "$mode" in
  pack)
    cmake --preset release >/dev/null
    cmake --build --preset release --target neuflow-gpu-check
    binary=build/release/tests/model/neuflow-gpu-check
    rm -rf "$dir/bundle" "$dir/bundle.tar.xz"
    mkdir -p "$dir/bundle/bin" "$dir/bundle/lib"
    cp "$binary" "$dir/bundle/bin/"
    # Every library it loads but the Vulkan loader (packed apart, below) and the vDSO.
    ldd "$binary" | awk '/=> \// {print $3} $1 ~ /^\/.*ld-linux/ {print $1}' | grep -v 'libvulkan\.so' |
      while read -r lib; do cp -L "$lib" "$dir/bundle/lib/"; done
    # Debian's Vulkan loader, which this glibc runs; it finds the GPU's driver by its ICD file.
    tmp=$(mktemp -d)
    (cd "$tmp" && apt-get download libvulkan1 >/dev/null 2>&1) || { say "apt-get download libvulkan1 failed"; exit 1; }
    dpkg -x "$tmp"/libvulkan1_*.deb "$tmp/root"
    cp -L "$tmp"/root/usr/lib/*/libvulkan.so.1 "$dir/bundle/lib/"
    rm -rf "$tmp"
    tar -C "$dir" -cJf "$dir/bundle.tar.xz" bundle
    rm -rf "$dir/bundle"
    say "packed $(du -h "$dir/bundle.tar.xz" | cut -f1) into $dir/bundle.tar.xz; on the GPU machine:" \
        "bash scripts/gpu-check.sh run $dir (carry $dir)"
    ;;
  run)
    shift $(( $# >= 2 ? 2 : $# ))
    [ -f "$dir/bundle.tar.xz" ] || { say "no $dir/bundle.tar.xz: run 'bash scripts/gpu-check.sh pack' where the project builds"; exit 1; }
    work=$(mktemp -d /tmp/neuflow-gpu-check.XXXXXX)
    tar -C "$work" -xJf "$dir/bundle.tar.xz"
    lib=$work/bundle/lib
    # The NVIDIA driver's ICD file where the lent machine keeps it, when the loader's usual
    # folders have none.
    if [ -z "${VK_DRIVER_FILES:-}${VK_ICD_FILENAMES:-}" ] && ! ls /usr/share/vulkan/icd.d/*.json /etc/vulkan/icd.d/*.json >/dev/null 2>&1; then
      for icd in /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json /usr/share/vulkan/icd.d/nvidia_icd.json; do
        if [ -f "$icd" ]; then export VK_DRIVER_FILES=$icd; break; fi
      done
    fi
    if command -v nvidia-smi >/dev/null; then
      nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader || true
    fi
    [ $# -gt 0 ] || set -- --check-size 768x432 --sizes 768x432,1024x448 --frames 30
    status=0
    timeout 470 "$lib"/ld-linux-x86-64.so.2 --library-path "$lib" "$work/bundle/bin/neuflow-gpu-check" "$@" \
      | tee "${OUT:-$work}/gpu-check.txt" || status=$?
    rm -rf "$work"
    exit "$status"
    ;;
  *)
    sed -n '2,18p' "$0" | sed 's/^# \{0,1\}//'
    exit 64
    ;;
esac
