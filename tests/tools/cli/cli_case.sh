#!/usr/bin/env bash
# One end-to-end case of the `neuflow` command, for ctest.
#   cli_case.sh CASE NEUFLOW_BIN FLOW_GT_DIR WORK_DIR [ARGS...]
# Exit 0 = pass, 77 = skipped (a fixture is missing and NEUFLOW_REQUIRE_FIXTURES is not set),
# anything else = fail. $NEUFLOW_SHARED_DIR at run time overrides FLOW_GT_DIR.
set -u
case_name=$1 bin=$2 gt=$3 work=$4
shift 4
if [[ -n "${NEUFLOW_SHARED_DIR:-}" ]]; then gt="$NEUFLOW_SHARED_DIR/fixtures/flow-gt"; fi
rm -rf "$work" && mkdir -p "$work" || exit 1

fail() { echo "FAIL: $*"; exit 1; }

need_fixture() {
  [[ -e "$gt/$1" ]] && return 0
  if [[ -n "${NEUFLOW_REQUIRE_FIXTURES:-}" && "${NEUFLOW_REQUIRE_FIXTURES}" != 0 ]]; then
    fail "fixture $gt/$1 is missing and NEUFLOW_REQUIRE_FIXTURES is set"
  fi
  echo "SKIP: fixture $gt/$1 not found (set NEUFLOW_SHARED_DIR to the folder holding fixtures/)"
  exit 77
}

# Runs the command, shows its output, and fails unless it exits with the expected status.
run_expect() {
  local want=$1
  shift
  "$@" >"$work/stdout" 2>"$work/stderr"
  local got=$?
  echo "\$ $*"
  cat "$work/stdout"
  cat "$work/stderr" >&2
  [[ $got -eq $want ]] || fail "exit status $got, expected $want"
}

expect_stdout() { grep -Eq -- "$1" "$work/stdout" || fail "stdout does not match /$1/"; }
expect_stderr() { grep -Eq -- "$1" "$work/stderr" || fail "stderr does not match /$1/"; }

is_png() { [[ "$(head -c 8 "$1" | od -An -tx1 | tr -d ' \n')" == 89504e470d0a1a0a ]]; }
# A PNG's width and height from its IHDR chunk: "WxH".
png_size() { echo "$(( 0x$(od -An -tx1 -j16 -N4 "$1" | tr -d ' \n') ))x$(( 0x$(od -An -tx1 -j20 -N4 "$1" | tr -d ' \n') ))"; }

case "$case_name" in
  viz)  # viz FIXTURE: renders it, per-image normalization and a fixed maximum
    need_fixture "$1"
    run_expect 0 "$bin" viz "$gt/$1" -o "$work/auto.png"
    is_png "$work/auto.png" || fail "auto.png is not a PNG"
    expect_stdout "^max flow: [0-9]+\.[0-9]+ px \(largest valid magnitude"
    run_expect 0 "$bin" viz "$gt/$1" -o "$work/fixed.png" --max-flow 20
    is_png "$work/fixed.png" || fail "fixed.png is not a PNG"
    expect_stdout "^max flow: 20\.000 px \(fixed"
    # Without -o: beside the input, its name plus .png.
    cp "$gt/$1" "$work/$(basename "$1")"
    run_expect 0 "$bin" viz "$work/$(basename "$1")"
    is_png "$work/$(basename "$1").png" || fail "viz without -o wrote no $(basename "$1").png"
    expect_stdout "wrote .*$(basename "$1")\.png"
    ;;
  compare_self)  # compare_self FIXTURE: EPE 0, Fl 0
    need_fixture "$1"
    run_expect 0 "$bin" compare "$gt/$1" "$gt/$1"
    expect_stdout "^EPE +0\.0000 px$"
    expect_stdout "^Fl-all +0\.00 %$"
    expect_stdout "^<3px +100\.00 %$"
    expect_stdout "^valid +[1-9][0-9]* of [0-9]+ px$"
    run_expect 0 "$bin" compare --json "$gt/$1" "$gt/$1"
    expect_stdout '^\{"epe": 0, "fl_all": 0, "within_1px": 1, .*"valid_pixels": [1-9]'
    ;;
  image_as_flow)  # image_as_flow FIXTURE: an 8-bit rendering given where a KITTI flow is due
    need_fixture "$1"
    run_expect 0 "$bin" viz "$gt/$1" -o "$work/rendering.png"
    run_expect 65 "$bin" compare "$work/rendering.png" "$gt/$1"
    expect_stderr "16 bits per channel"
    ;;
  size_mismatch)  # size_mismatch A B
    need_fixture "$1"
    need_fixture "$2"
    run_expect 65 "$bin" compare "$gt/$1" "$gt/$2"
    expect_stderr "is [0-9]+x[0-9]+ but .* is [0-9]+x[0-9]+"
    ;;
  viz_pictures)  # viz_pictures FLOW IMAGE OTHER_IMAGE: --key, --arrows and --overlay, as the element draws them
    need_fixture "$1"
    need_fixture "$2"
    need_fixture "$3"
    run_expect 0 "$bin" viz "$gt/$1" -o "$work/plain.png" --max-flow 5
    size=$(png_size "$work/plain.png")
    for extra in "--key" "--arrows" "--arrows --arrow-spacing 12" "--overlay $gt/$2" "--overlay $gt/$2 --alpha 0.3 --key --arrows"; do
      # shellcheck disable=SC2086  # the options are words
      run_expect 0 "$bin" viz "$gt/$1" -o "$work/extra.png" --max-flow 5 $extra
      [[ "$(png_size "$work/extra.png")" == "$size" ]] || fail "viz $extra: $(png_size "$work/extra.png"), not $size"
      ! cmp -s "$work/plain.png" "$work/extra.png" || fail "viz $extra drew nothing more than the plain rendering"
    done
    run_expect 0 "$bin" viz "$gt/$1" -o "$work/opaque.png" --max-flow 5 --overlay "$gt/$2" --alpha 1
    cmp -s "$work/plain.png" "$work/opaque.png" || fail "--alpha 1 is not the rendering alone"
    run_expect 65 "$bin" viz "$gt/$1" -o "$work/bad.png" --overlay "$gt/$3"
    expect_stderr "--overlay .* is [0-9]+x[0-9]+ but the flow is ${size}"
    run_expect 66 "$bin" viz "$gt/$1" -o "$work/bad.png" --overlay "$work/none.png"
    expect_stderr "cannot read it as an image"
    run_expect 64 "$bin" viz "$gt/$1" -o "$work/bad.png" --alpha 0.5  # without --overlay: nothing to blend over
    run_expect 64 "$bin" viz "$gt/$1" -o "$work/bad.png" --arrow-spacing 12
    [[ ! -e "$work/bad.png" ]] || fail "a picture was written for a bad --overlay"
    ;;
  compare_error_map)  # compare_error_map FLOW: the error map of a flow against itself (the map's colours: flow_tests)
    need_fixture "$1"
    run_expect 0 "$bin" compare "$gt/$1" "$gt/$1" --error-map "$work/self.png"
    is_png "$work/self.png" || fail "self.png is not a PNG"
    expect_stdout "^wrote .*self\.png"
    run_expect 0 "$bin" viz "$gt/$1" -o "$work/rendering.png"
    [[ "$(png_size "$work/self.png")" == "$(png_size "$work/rendering.png")" ]] || fail "the map is not the flow's size"
    run_expect 0 "$bin" compare --json "$gt/$1" "$gt/$1" --error-map "$work/json.png"
    [[ "$(head -c 1 "$work/stdout")" == "{" && "$(wc -l < "$work/stdout")" -eq 1 ]] || fail "--json printed more than JSON"
    run_expect 64 "$bin" compare "$gt/$1" "$gt/$1" --error-map "$work/map.jpg"
    expect_stderr "give it a \.png name"
    ;;
  missing)  # a missing input: exit 66 (EX_NOINPUT) from both subcommands
    run_expect 66 "$bin" compare "$work/none.flo" "$work/none.flo"
    expect_stderr "none\.flo: no such file"
    run_expect 66 "$bin" viz "$work/none.npy" -o "$work/out.png"
    [[ ! -e "$work/out.png" ]] || fail "an output was written for a missing input"
    ;;
  malformed)  # a malformed input: exit 65 (EX_DATAERR)
    printf 'PIEH\x10\x00\x00\x00\x10\x00\x00\x00short' >"$work/bad.flo"
    run_expect 65 "$bin" compare "$work/bad.flo" "$work/bad.flo"
    expect_stderr "bad\.flo: truncated"
    printf 'not a flow' >"$work/bad.npy"
    run_expect 65 "$bin" viz "$work/bad.npy" -o "$work/out.png"
    expect_stderr "wrong magic"
    printf 'x' >"$work/flow.txt"
    run_expect 65 "$bin" viz "$work/flow.txt" -o "$work/out.png"
    expect_stderr "unknown flow file extension"
    ;;
  unwritable)  # the output cannot be created: exit 73 (EX_CANTCREAT), nothing left behind
    printf 'PIEH\x01\x00\x00\x00\x01\x00\x00\x00\x00\x00\x80\x3f\x00\x00\x00\x00' >"$work/one.flo"
    run_expect 73 "$bin" viz "$work/one.flo" -o "$work/no/such/dir/out.png"
    run_expect 0 "$bin" viz "$work/one.flo" -o "$work/one.png"
    expect_stdout "^max flow: 1\.000 px"
    mkdir "$work/dir.png"
    run_expect 73 "$bin" viz "$work/one.flo" -o "$work/dir.png"
    [[ "$(ls -A "$work" | sort | tr '\n' ' ')" == "dir.png one.flo one.png stderr stdout " ]] ||
      fail "unexpected files left: $(ls -A "$work")"
    ;;
  *)
    fail "unknown case $case_name"
    ;;
esac
echo "PASS"
