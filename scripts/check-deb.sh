#!/usr/bin/env bash
# Builds the Debian packages neuflow and neuflow-dev from a build folder (CPack,
# cmake/NeuflowPackaging.cmake) and tries them as a user would:
#   - neuflow-dev: a program outside the project (tests/package/consumer) configured with
#     find_package(neuflow) against the package's contents, built, and run on the fixture model;
#   - neuflow (and python3-neuflow where the build has the Python module): installed with
#     `apt-get install ./neuflow_*.deb ./python3-neuflow_*.deb` into a clean Debian 12 root made
#     for the test (mmdebstrap, from Debian's archive), which pulls in their dependencies; there
#     tests/package/installed_checks.sh runs (gst-inspect-1.0 without GST_PLUGIN_PATH, neuflowd
#     --check-config on the examples in /etc/neuflow, systemd-analyze verify on the units, the
#     user and group, a flow and a gst-launch pipeline, the units enabled, `import neuflow` and a
#     flow from Python); then the packages are purged and nothing of them may remain, no link to
#     the units either.
#
# Usage: bash scripts/check-deb.sh [--packages-only] [BUILD_DIR]   (BUILD_DIR: build/release)
#   --packages-only  build the packages only (build/release/packages), as the README's command
set -euo pipefail
cd "$(dirname "$0")/.."

packages_only=0
if [ "${1:-}" = "--packages-only" ]; then packages_only=1; shift; fi
case "${1:-}" in -*) echo "usage: $0 [--packages-only] [BUILD_DIR]" >&2; exit 64 ;; esac
build=${1:-build/release}
[ -f "$build/CPackConfig.cmake" ] || { echo "check-deb: $build is not a configured build folder (cmake --preset release)" >&2; exit 66; }
build=$(cd "$build" && pwd)
say() { echo "check-deb: $*"; }

# --- the packages ---------------------------------------------------------------------------
rm -rf "$build/packages"
(cd "$build" && cpack -G DEB > cpack.log) || { cat "$build/cpack.log"; exit 1; }
deb=$(ls "$build"/packages/neuflow_*.deb)
dev_deb=$(ls "$build"/packages/neuflow-dev_*.deb)
python_deb=$(ls "$build"/packages/python3-neuflow_*.deb 2>/dev/null || true)  # none with NEUFLOW_BUILD_PYTHON=OFF
say "built $(basename "$deb") ($(du -k "$deb" | cut -f1) KiB), $(basename "$dev_deb") ($(du -k "$dev_deb" | cut -f1) KiB)" \
    "${python_deb:+and $(basename "$python_deb") ($(du -k "$python_deb" | cut -f1) KiB) }in $build/packages"
[ "$packages_only" -eq 1 ] && exit 0

work=$(pwd)/build/deb
rm -rf "$work" && mkdir -p "$work"

# --- neuflow-dev: find_package(neuflow) from a consumer's own build -------------------------
shared=${NEUFLOW_SHARED_DIR:-$(pwd)/../shared}
checkpoint="$shared/fixtures/neuflow-v2-seed0/checkpoint.pth"
if [ ! -f "$checkpoint" ]; then
  if [ "${NEUFLOW_REQUIRE_FIXTURES:-0}" = 1 ]; then say "the fixture model is missing: $checkpoint" >&2; exit 1; fi
  say "the fixture model is missing ($checkpoint): the packages' programs are checked without running the network"
  checkpoint=""
fi
mkdir -p "$work/dev-root"
dpkg-deb -x "$deb" "$work/dev-root"
dpkg-deb -x "$dev_deb" "$work/dev-root"
cmake -S tests/package/consumer -B "$work/consumer" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$work/dev-root/usr" > "$work/consumer.log" || { cat "$work/consumer.log"; exit 1; }
grep -q "$work/dev-root/usr/lib/cmake/neuflow" "$work/consumer/CMakeCache.txt" ||
  { say "the consumer found a neuflow package other than neuflow-dev's" >&2; exit 1; }
cmake --build "$work/consumer" >> "$work/consumer.log" || { cat "$work/consumer.log"; exit 1; }
if [ -n "$checkpoint" ]; then
  "$work/consumer/neuflow_consumer" "$checkpoint" "$work/consumer/flow.flo"
fi
say "neuflow-dev: a find_package(neuflow) consumer builds against the package${checkpoint:+ and computes flow}"

# --- neuflow: apt-get install into a clean Debian 12 root -----------------------------------
data="$work/data"
mkdir -p "$data"
cp "$deb" ${python_deb:+"$python_deb"} tests/package/installed_checks.sh "$data/"
installs="/tmp/neuflow-check/$(basename "$deb")${python_deb:+ /tmp/neuflow-check/$(basename "$python_deb")}"
if [ -n "$checkpoint" ]; then
  cp "$checkpoint" "$data/checkpoint.pth"
  frames=("$shared"/fixtures/frames/*.jpg)
  cp "${frames[0]}" "$data/frame0.jpg"
  cp "${frames[1]}" "$data/frame1.jpg"
fi
bash scripts/install-deps.sh mmdebstrap
start=$(date +%s)
# systemd (systemd-analyze) and gstreamer1.0-tools (gst-inspect-1.0, gst-launch-1.0) are the
# test's tools; pkg-config tells where GStreamer looks for plugins. Everything else comes from
# the package's dependencies.
# The root lives only while mmdebstrap runs (TARGET /dev/null): nothing is left to clean up,
# and as a user (unshare mode, in a user namespace) nothing owned by other ids either.
mmdebstrap --quiet --variant=apt --mode="$([ "$(id -u)" -eq 0 ] && echo root || echo unshare)" \
  --include=systemd,gstreamer1.0-tools,pkgconf,libgstreamer1.0-dev \
  --dpkgopt='path-exclude=/usr/share/man/*' --dpkgopt='path-exclude=/usr/share/locale/*' \
  --customize-hook='mkdir -p "$1/tmp/neuflow-check"' \
  --customize-hook="copy-in $(cd "$data" && ls | sed "s|^|$data/|" | tr '\n' ' ') /tmp/neuflow-check" \
  --customize-hook="chroot \"\$1\" apt-get install -y --no-install-recommends $installs" \
  --customize-hook='chroot "$1" bash /tmp/neuflow-check/installed_checks.sh /tmp/neuflow-check' \
  --customize-hook="chroot \"\$1\" sh -c \"dpkg -L neuflow${python_deb:+ python3-neuflow} > /tmp/neuflow-check/files\"" \
  --customize-hook="chroot \"\$1\" apt-get purge -y neuflow${python_deb:+ python3-neuflow}" \
  --customize-hook='chroot "$1" sh -c "left=0; while read -r f; do if [ -e \"\$f\" ] && [ ! -d \"\$f\" ]; then echo \"left behind: \$f\"; left=1; fi; done < /tmp/neuflow-check/files; [ ! -e /etc/neuflow ] || { echo \"left behind: /etc/neuflow\"; left=1; }; [ ! -e /usr/lib/python3/dist-packages/neuflow ] || { echo \"left behind: /usr/lib/python3/dist-packages/neuflow\"; left=1; }; links=\$(find /etc/systemd/system -name \"neuflowd*\"); [ -z \"\$links\" ] || { echo \"left behind: \$links\"; left=1; }; exit \$left"' \
  bookworm /dev/null
say "neuflow${python_deb:+ and python3-neuflow}: installed with their dependencies into a clean Debian 12 root, checked, purged" \
    "without leftovers ($(( $(date +%s) - start )) s)"
