#!/usr/bin/env bash
# Installs the Debian 12 packages that neuflow's build, tests and benchmarks need, or, given
# package names, those instead (scripts/check-arm64.sh's host tools).
# Idempotent: does nothing when everything is already installed.
# Usage: bash scripts/install-deps.sh [PACKAGE...]
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git
  libdnnl-dev                       # oneDNN: convolutions and matrix products
  libvulkan-dev libvulkan-volk-dev glslc spirv-tools   # the Vulkan backend: headers, run-time loader, shader compiler, spirv-val
  mesa-vulkan-drivers vulkan-validationlayers vulkan-tools   # its tests: lavapipe, validation, vulkaninfo
  libopencv-core-dev libopencv-imgproc-dev libopencv-imgcodecs-dev libopencv-video-dev
  libzip-dev                        # the zip container of PyTorch checkpoints
  libpng-dev                        # flow/: KITTI flow PNGs and renderings
  libjpeg-dev                       # the neuflow command: a JPEG's size read from its header before decoding
  libcli11-dev                      # command-line parsing
  libgstreamer1.0-dev libgstreamer-plugins-base1.0-dev   # the GStreamer plugin
  gstreamer1.0-plugins-base gstreamer1.0-plugins-good gstreamer1.0-tools
  gstreamer1.0-plugins-bad          # intervideo (RTSP mounts), h264parse, waylandsink
  gstreamer1.0-x                    # ximagesink: a neuflowd display sink under X11
  gstreamer1.0-plugins-ugly         # x264enc: the encoded visualization
  gstreamer1.0-libav                # decoders for common video files (e.g. vtest.avi's MS-MPEG4)
  gstreamer1.0-rtsp libgstrtspserver-1.0-dev   # neuflowd's RTSP server mounts
  gstreamer1.0-libcamera            # libcamerasrc: CSI cameras
  libsystemd-dev                    # sd_notify: READY/WATCHDOG/STATUS
  libtomlplusplus-dev               # neuflowd's config file
  libsoup-3.0-dev                   # neuflowd's Prometheus metrics endpoint
  libcurl4-openssl-dev libssl-dev   # neuflow fetch-model: download + SHA-1 verification
  opencv-doc                        # sample video (vtest.avi) for the quick-start job
  systemd                           # systemd-analyze verify of the unit files
  libgtest-dev libgmock-dev libbenchmark-dev
  clang-14 libclang-rt-14-dev libomp-14-dev llvm-14   # libFuzzer harnesses (tests/fuzz), llvm-symbolizer
  clang-format-14 clang-tidy-14     # CI's first stage: .clang-format, .clang-tidy
  g++-11                            # JetPack 6's compiler: CI compiles the core with it
  python3 python3-numpy             # tests check that numpy reads our .npy files
  python3-dev pybind11-dev          # the Python module (python/)
  python3-pytest python3-opencv     # its tests and examples
)
if [ $# -gt 0 ]; then packages=("$@"); fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

sudo=""
if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
# CI starts two of these at once (the arm64 and Ubuntu roots' host tools): the second waits for
# the first rather than failing on apt's lock.
exec 9>"${TMPDIR:-/tmp}/neuflow-install-deps.lock"
flock 9
echo "install-deps: installing ${missing[*]}"
$sudo apt-get update -q
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
