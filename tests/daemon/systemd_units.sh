#!/usr/bin/env bash
# Checks neuflowd's systemd units with systemd's own tools, offline (no running systemd needed).
#
#   systemd_units.sh verify    UNITS_SRC NEUFLOWD WORK   systemd-analyze verify, both units
#   systemd_units.sh security  UNITS_SRC NEUFLOWD WORK   systemd-analyze security exposure ≤ 2.0
#   systemd_units.sh alike     UNITS_SRC NEUFLOWD WORK   the template hardened like the unit
#   systemd_units.sh installed BUILD_DIR NEUFLOWD WORK   the units `cmake --install` writes
#
# The units are configured as systemd/CMakeLists.txt does at install time, with ExecStart= pointing at
# the built neuflowd (verify checks that it exists and is executable). Exit 77: skipped.
set -uo pipefail
mode=$1 src=$2 neuflowd=$3 work=$4

fail() { echo "FAIL: $*"; exit 1; }
if [ "$mode" != alike ]; then
  command -v systemd-analyze > /dev/null || { echo "SKIP: systemd-analyze is not installed"; exit 77; }
  [ -x "$neuflowd" ] || fail "$neuflowd is not built"
fi

rm -rf "$work"
mkdir -p "$work" || fail "cannot create $work"

configure() {  # UNIT.in → $work/UNIT
  local unit=$1 from=$2
  sed -e "s|@NEUFLOWD@|$neuflowd|g" -e "s|@GST_PLUGIN_DIR@|$(dirname "$neuflowd")/../plugins|g" \
    "$from/$unit.in" > "$work/$unit" || fail "cannot configure $unit"
  if grep -n '@[A-Z_]*@' "$work/$unit"; then fail "$unit: placeholder left unconfigured"; fi
}

# Runs `systemd-analyze verify` on a unit (or FILE:INSTANCE). Every complaint that names one of
# our units is a failure: verify exits 0 on unknown keys and bad values, it only warns.
verify() {
  local target=$1 out rc
  out=$(systemd-analyze verify --man=no "$target" 2>&1)
  rc=$?
  local ours
  ours=$(grep -E "neuflowd|$work" <<<"$out")
  if [ $rc -ne 0 ] || [ -n "$ours" ]; then
    echo "$out"
    fail "systemd-analyze verify $target (exit $rc)"
  fi
  if [ -n "$out" ]; then echo "note (about other units): $out"; fi
  echo "ok: systemd-analyze verify $(basename "$target")"
}

case $mode in
  verify)
    configure neuflowd.service "$src"
    configure neuflowd@.service "$src"
    # A unit with a mistake must be reported here, or a silent verify would prove nothing.
    sed 's/^DevicePolicy=closed/&\nDevicePolicyy=closed/' "$work/neuflowd.service" > "$work/neuflowd-canary.service"
    canary=$(systemd-analyze verify --man=no "$work/neuflowd-canary.service" 2>&1)
    grep -q "DevicePolicyy" <<<"$canary" ||
      fail "systemd-analyze verify does not report an unknown key here, so it cannot check the units"
    rm "$work/neuflowd-canary.service"

    verify "$work/neuflowd.service"
    verify "$work/neuflowd@.service"
    verify "$work/neuflowd@.service:neuflowd@front.service"  # a named instance (%i = front)
    ;;

  security)
    configure neuflowd.service "$src"
    configure neuflowd@.service "$src"
    systemd-analyze security --help 2>&1 | grep -q -- '--offline' ||
      { echo "SKIP: this systemd-analyze cannot assess units offline"; exit 77; }
    cp "$work/neuflowd@.service" "$work/neuflowd@front.service"
    for unit in neuflowd.service neuflowd@front.service; do
      # The units rate 1.6 today (what a camera daemon needs: devices, network, JIT code).
      # --threshold is in tenths: above 2.0 means a setting was dropped by mistake (the
      # syscall filter, the capability bound, the kernel protections each push it over).
      if ! out=$(systemd-analyze security --offline=true --threshold=20 --no-pager "$work/$unit" 2>&1); then
        echo "$out"
        fail "$unit is exposed more than 2.0 (see ✗ above)"
      fi
      echo "ok: $(tail -n 1 <<<"$out")"
    done
    ;;

  alike)
    # Instances must not drift from the single unit: only the lines naming the config and
    # the per-instance folders may differ.
    strip() {
      grep -vE '^(#|$|Description=|ExecStart=|Environment=GST_REGISTRY_1_0=|StateDirectory=|CacheDirectory=|RuntimeDirectory=)' "$1"
    }
    if ! diff <(strip "$src/neuflowd.service.in") <(strip "$src/neuflowd@.service.in"); then
      fail "neuflowd@.service differs from neuflowd.service beyond its instance lines (diff above)"
    fi
    grep -q '^ExecStart=.*--config /etc/neuflow/%i.toml$' "$src/neuflowd@.service.in" ||
      fail "neuflowd@.service does not read /etc/neuflow/%i.toml"
    for key in StateDirectory CacheDirectory RuntimeDirectory; do
      grep -q "^$key=neuflow/%i$" "$src/neuflowd@.service.in" || fail "neuflowd@.service: $key is not per instance"
    done
    echo "ok: the template is hardened like neuflowd.service"
    ;;

  installed)
    # Only neuflowd and the units, each from its own folder of the build tree.
    build=$src
    prefix="$work/prefix"
    [ -f "$build/systemd/cmake_install.cmake" ] ||
      fail "$build/systemd has no install rules: is add_subdirectory(systemd) in the top-level CMakeLists.txt?"
    for part in daemon systemd; do
      cmake --install "$build/$part" --prefix "$prefix" > "$work/install.log" 2>&1 ||
        { cat "$work/install.log"; fail "cmake --install $build/$part"; }
    done
    units="$prefix/lib/systemd/system"
    for unit in neuflowd.service neuflowd@.service; do
      [ -f "$units/$unit" ] || fail "$unit not installed under $units"
      grep -q "^ExecStart=$prefix/bin/neuflowd " "$units/$unit" ||
        fail "$unit: ExecStart= does not start the installed $prefix/bin/neuflowd"
      # The plugin's folder: GStreamer's own (pkg-config's pluginsdir) under the prefix.
      gst_prefix=$(pkg-config --variable=prefix gstreamer-1.0)
      plugins="$prefix/$(pkg-config --variable=pluginsdir gstreamer-1.0 | sed "s|^$gst_prefix/||")"
      grep -q "^Environment=GST_PLUGIN_PATH_1_0=$plugins\$" "$units/$unit" ||
        fail "$unit: GST_PLUGIN_PATH_1_0 is not the installed plugin's folder $plugins"
      verify "$units/$unit"
      grep -q '^Group=neuflow$' "$units/$unit" || fail "$unit: not run in the group neuflow"
    done
    sysusers="$prefix/lib/sysusers.d/neuflow.conf"
    [ -f "$sysusers" ] || fail "the sysusers.d file that creates the group neuflow is not installed ($sysusers)"
    if command -v systemd-sysusers > /dev/null; then
      # Against an empty tree (--root), so nothing is created on this machine: --dry-run where
      # systemd has it (250 and later); on 249 (Ubuntu 22.04, JetPack 6) the group is really
      # created in that tree and read back from its /etc/group.
      mkdir -p "$work/root/etc"
      if systemd-sysusers --help 2>&1 | grep -q -- '--dry-run'; then
        out=$(systemd-sysusers --root="$work/root" --dry-run "$sysusers" 2>&1) ||
          { echo "$out"; fail "systemd-sysusers rejects $sysusers"; }
        grep -q "neuflow" <<<"$out" || { echo "$out"; fail "systemd-sysusers would not create the group neuflow"; }
        echo "ok: systemd-sysusers would create: $out"
      else
        out=$(systemd-sysusers --root="$work/root" "$sysusers" 2>&1) ||
          { echo "$out"; fail "systemd-sysusers rejects $sysusers"; }
        grep -q '^neuflow:' "$work/root/etc/group" 2>/dev/null ||
          { echo "$out"; fail "systemd-sysusers did not create the group neuflow"; }
        echo "ok: systemd-sysusers created: $(grep '^neuflow:' "$work/root/etc/group")"
      fi
    fi
    ;;

  *)
    fail "unknown mode $mode"
    ;;
esac
