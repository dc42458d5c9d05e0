#!/usr/bin/env bash
# `neuflow flow --backend vulkan` when the GPU fails: a device that does not exist, and a device
# lost while the network runs (NEUFLOW_VULKAN_LOSE_DEVICE_AFTER stands in for a GPU hang or
# reset). Each exits 69 (EX_UNAVAILABLE) with a message naming the device and the cause, and
# writes no output file.
# Usage: flow_command_vulkan_test.sh NEUFLOW_BINARY
set -u
neuflow=$1
source "$(dirname "$0")/../support/require.sh"
fixture="$(neuflow_fixtures)/neuflow-v2-seed0"
require_fixture "$fixture/checkpoint.pth"
require_vulkan "$neuflow"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
frames=("$fixture/frame0.png" "$fixture/frame1.png")

"$neuflow" flow --backend vulkan --device 63 -m "$fixture/checkpoint.pth" "${frames[@]}" "$out/a.flo" 2> "$out/err"
status=$?
cat "$out/err"
[ "$status" -eq 69 ] || fail "a Vulkan device that does not exist must exit 69, not $status"
grep -q "no Vulkan device 63" "$out/err" || fail "the error must name device 63"
[ ! -e "$out/a.flo" ] || fail "no flow may be written"

NEUFLOW_VULKAN_LOSE_DEVICE_AFTER=1 "$neuflow" flow --backend vulkan --device 0 --iters-s16 1 --iters-s8 1 \
  -m "$fixture/checkpoint.pth" "${frames[@]}" "$out/b.flo" 2> "$out/err"
status=$?
cat "$out/err"
[ "$status" -eq 69 ] || fail "a lost device must exit 69, not $status"
grep -q "vulkan device 0" "$out/err" || fail "the error must name vulkan device 0"
grep -q "lost" "$out/err" || fail "the error must say the device was lost"
[ ! -e "$out/b.flo" ] || fail "no flow may be written"
echo "ok"
