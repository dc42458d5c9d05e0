#!/usr/bin/env bash
# Installs the build into a temporary prefix and checks that the plugin lands in GStreamer's
# own plugin folder under it (pkg-config's pluginsdir, relative to GStreamer's prefix) and that
# GStreamer loads it from there (no build tree on any search path).
# Usage: install_test.sh BUILD_DIR GST_INSPECT PLUGIN_DIR
set -euo pipefail
build=$1
inspect=$2
plugin_dir=$3
prefix=$(mktemp -d)
trap 'rm -rf "$prefix"' EXIT
cmake --install "$build" --prefix "$prefix" > /dev/null
# PLUGIN_DIR is what CMake took from the target's pkg-config (a cross build's sysroot has its
# own), so the host's pkg-config is asked only when it describes the same machine.
if [ "$(uname -m)-linux-gnu" = "$(basename "$(dirname "$plugin_dir")")" ] || [ "$plugin_dir" = "lib/gstreamer-1.0" ]; then
  expected=$(pkg-config --variable=pluginsdir gstreamer-1.0)
  gst_prefix=$(pkg-config --variable=prefix gstreamer-1.0)
  [ "$plugin_dir" = "${expected#"$gst_prefix"/}" ] ||
    { echo "FAIL: the plugin's folder $plugin_dir is not GStreamer's pluginsdir $expected under the prefix"; exit 1; }
fi
plugin="$prefix/$plugin_dir/libgstneuflow.so"
[ -f "$plugin" ] || { echo "FAIL: libgstneuflow.so not installed as $plugin"; find "$prefix" -name '*.so'; exit 1; }
echo "installed: $plugin"
# gst-inspect's Origin URL and Doc-uri point at the documentation installed beside it.
for doc in README.md LICENSE docs/benchmarks.md; do
  [ -f "$prefix/share/doc/neuflow/$doc" ] || { echo "FAIL: share/doc/neuflow/$doc not installed"; exit 1; }
done
unset GST_PLUGIN_PATH GST_PLUGIN_PATH_1_0
if ! output=$(GST_PLUGIN_PATH_1_0=$(dirname "$plugin") GST_REGISTRY_1_0="$prefix/registry.bin" "$inspect" neuflow 2>&1) \
    || ! grep -q "iters-s8" <<<"$output"; then
  echo "FAIL: gst-inspect-1.0 cannot load the installed plugin:"
  echo "$output" | head -n 20
  exit 1
fi
echo "gst-inspect-1.0 loads the installed plugin"
