#!/usr/bin/env bash
# Run inside a clean Debian root after `apt-get install ./neuflow_*.deb` (scripts/check-deb.sh):
# what a user of the package relies on, with nothing of the build tree and no GST_PLUGIN_PATH.
# Usage: installed_checks.sh DIR   (DIR holds checkpoint.pth, frame0.jpg and frame1.jpg, or is
# empty: then nothing runs the network)
set -euo pipefail
data=$1
fail() { echo "installed-checks: FAIL: $*" >&2; exit 1; }
ok() { echo "installed-checks: ok: $*"; }
unset GST_PLUGIN_PATH GST_PLUGIN_PATH_1_0 GST_PLUGIN_SYSTEM_PATH GST_PLUGIN_SYSTEM_PATH_1_0

plugin=$(dpkg -L neuflow | grep '/gstreamer-1.0/libgstneuflow.so$') || fail "the package has no GStreamer plugin"
gst_dir=$(pkg-config --variable=pluginsdir gstreamer-1.0 2>/dev/null || dirname "$(dpkg -L libgstreamer1.0-0 | grep '/gstreamer-1.0$' | head -1)/x")
[ "$(dirname "$plugin")" = "$gst_dir" ] || fail "the plugin is in $(dirname "$plugin"), GStreamer's own plugins in $gst_dir"
for file in /usr/bin/neuflow /usr/bin/neuflowd /usr/bin/neuflow-shm-reader "$plugin"; do
  [ -f "$file" ] || fail "$file is not installed"
  missing=$(ldd "$file" | grep "not found" || true)
  [ -z "$missing" ] || fail "$file needs libraries the package's dependencies did not bring: $missing"
done
ok "the programs and the plugin find every library they link ($(dpkg-query -W -f='${Depends}' neuflow | tr ',' '\n' | wc -l) dependencies)"

neuflow --version
for element in neuflow neuflowviz neuflowsink; do
  inspect=$(gst-inspect-1.0 "$element" 2>&1) ||
    { echo "$inspect"; fail "gst-inspect-1.0 $element: GStreamer does not find the element"; }
  # By its path through /lib or /usr/lib (merged /usr): the same file either way.
  loaded=$(sed -n 's/^ *Filename *//p' <<<"$inspect")
  [ "$loaded" -ef "$plugin" ] || fail "gst-inspect-1.0 $element: loaded from $loaded, not $plugin"
done
ok "gst-inspect-1.0 finds the plugin in $(dirname "$plugin") without GST_PLUGIN_PATH"

for config in /etc/neuflow/examples/*.toml; do
  out=$(neuflowd --check-config "$config" 2>&1) || { echo "$out"; fail "neuflowd --check-config $config"; }
  if grep -q "plugin .* was not found" <<<"$out"; then echo "$out"; fail "$config: neuflowd does not find the plugin"; fi
  ok "neuflowd --check-config $config: $(tail -1 <<<"$out")"
done
conffiles=$(dpkg-query -W -f='${Conffiles}' neuflow)
grep -q "/etc/neuflow/examples/test-pattern-to-mp4.toml" <<<"$conffiles" || fail "the example configs are not conffiles: $conffiles"

getent passwd neuflow > /dev/null || fail "the package made no user neuflow (sysusers.d)"
getent group neuflow > /dev/null || fail "the package made no group neuflow (sysusers.d)"
ok "user and group neuflow: $(id neuflow)"

# The units as installed: their ExecStart, plugin path and directives, checked by systemd.
units=/usr/lib/systemd/system
grep -q "^ExecStart=/usr/bin/neuflowd " "$units/neuflowd.service" || fail "neuflowd.service does not start /usr/bin/neuflowd"
grep -q "^Environment=GST_PLUGIN_PATH_1_0=$(dirname "$plugin")$" "$units/neuflowd.service" ||
  fail "neuflowd.service does not point GStreamer at $(dirname "$plugin")"
verify=$(SYSTEMD_LOG_LEVEL=warning systemd-analyze verify "$units/neuflowd.service" "$units/neuflowd@.service" 2>&1) ||
  { echo "$verify"; fail "systemd-analyze verify rejects the units"; }
ok "systemd-analyze verify: the units are valid${verify:+ ($verify)}"
# Enabled as an administrator would, so that removing the package must disable them
# (scripts/check-deb.sh looks for links left behind after the purge).
systemctl enable neuflowd.service neuflowd@front.service > /dev/null 2>&1 ||
  fail "systemctl enable neuflowd.service neuflowd@front.service"
[ -L /etc/systemd/system/multi-user.target.wants/neuflowd@front.service ] || fail "the template's instance was not enabled"

if [ -f "$data/checkpoint.pth" ]; then
  neuflow flow -m "$data/checkpoint.pth" --model-width 256 --model-height 144 --iters-s8 2 \
    "$data/frame0.jpg" "$data/frame1.jpg" /tmp/flow.flo
  [ -s /tmp/flow.flo ] || fail "neuflow flow wrote no flow"
  mkdir -p /tmp/gst-flows
  gst-launch-1.0 -q videotestsrc num-buffers=4 ! video/x-raw,width=64,height=48 ! videoconvert \
    ! neuflow model="$data/checkpoint.pth" iters-s8=1 ! neuflowsink location=/tmp/gst-flows/flow_%05d.flo ||
    fail "a gst-launch pipeline with the installed elements"
  flows=$(find /tmp/gst-flows -name '*.flo' | wc -l)
  [ "$flows" -eq 3 ] || fail "the pipeline wrote $flows flow files, not 3"
  ok "neuflow flow and a gst-launch pipeline compute flow with the installed core"
fi

# python3-neuflow, where it was installed beside: the interpreter finds it without PYTHONPATH.
if dpkg-query -W -f='${Status}' python3-neuflow 2>/dev/null | grep -q "install ok installed"; then
  module=$(cd / && python3 -c "import neuflow; print(neuflow.__file__)") || fail "python3 cannot import neuflow"
  case "$module" in /usr/lib/python3/dist-packages/neuflow/*) ;; *) fail "neuflow imported from $module" ;; esac
  if [ -f "$data/checkpoint.pth" ]; then
    flow_shape=$(cd / && python3 -c "
import neuflow, numpy as np
session = neuflow.Model('$data/checkpoint.pth', backend='cpu').session(iters_s8=1)
frame = np.random.default_rng(0).integers(0, 256, (48, 64, 3), dtype=np.uint8)
print(session.compute(frame, np.roll(frame, 2, axis=1)).shape)") || fail "python3-neuflow computes no flow"
    [ "$flow_shape" = "(48, 64, 2)" ] || fail "python3-neuflow's flow has the shape $flow_shape"
  fi
  ok "python3-neuflow: import neuflow from $module${flow_shape:+, a flow of $flow_shape}"
fi
