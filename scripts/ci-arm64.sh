#!/usr/bin/env bash
# The arm64 (aarch64) stage of CI: cross-build with Debian multiarch, then run the tests under
# qemu-user. Timings under emulation mean nothing and are not reported.
#   bash scripts/ci-arm64.sh [BUILD_DIR]
# What it proves and what it does not: README, "On a Jetson".
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build/arm64}
sudo=""
if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi

# ---- packages ---------------------------------------------------------------------------
if ! dpkg --print-foreign-architectures | grep -qx arm64; then
  $sudo dpkg --add-architecture arm64
fi
$sudo apt-get update -qq
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get install -y -qq crossbuild-essential-arm64 qemu-user-static >/dev/null

# Each group is tried on its own: a group whose :arm64 packages cannot sit beside the host's
# turns its part of the build off, and the log says which and why.
declare -A groups=(
  [core]="libc6-dev:arm64 libstdc++-12-dev:arm64 libgomp1:arm64 libdnnl-dev:arm64 libzip-dev:arm64 libopencv-core-dev:arm64 libopencv-imgproc-dev:arm64 libopencv-imgcodecs-dev:arm64 libopencv-video-dev:arm64 libgtest-dev:arm64 libgmock-dev:arm64"
  [gstreamer]="libgstreamer1.0-dev:arm64 libgstreamer-plugins-base1.0-dev:arm64 gstreamer1.0-plugins-base:arm64 gstreamer1.0-plugins-good:arm64"
  [cli]="libcurl4-openssl-dev:arm64 libssl-dev:arm64"
  [daemon]="libgstrtspserver-1.0-dev:arm64 libsystemd-dev:arm64 libtomlplusplus-dev:arm64 libsoup-3.0-dev:arm64"
)
declare -A have
for group in core gstreamer cli daemon; do
  if $sudo apt-get install -y -qq --no-install-recommends ${groups[$group]} >/tmp/neuflow-arm64-$group.log 2>&1; then
    have[$group]=1
    echo "ci-arm64: $group packages installed"
  else
    have[$group]=0
    echo "ci-arm64: the :arm64 packages of '$group' cannot be installed beside the host's; that part is built off:"
    grep -E "^E:|Conflicts|Breaks|but it is not going to be installed" /tmp/neuflow-arm64-$group.log | head -5 | sed 's/^/  /'
  fi
done
if [ "${have[core]}" != 1 ]; then
  echo "ci-arm64: the core (oneDNN, OpenCV, libzip for arm64) cannot be installed: nothing to build" >&2
  exit 1
fi
