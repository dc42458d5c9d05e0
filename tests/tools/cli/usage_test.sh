#!/usr/bin/env bash
# Usage errors of `neuflow`: exit 64 (EX_USAGE) with CLI11's message, an unknown option named
# before a missing required one, the help (exit 64) when no arguments are given.
# Usage: usage_test.sh NEUFLOW_BIN
set -u
neuflow=$1
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
fail() { echo "FAIL: $*"; echo "--- stderr:"; cat "$out/err"; exit 1; }

expect() {  # expect CODE PATTERN ARGS...: exit CODE and PATTERN (grep -E) on stderr
  local want=$1 pattern=$2
  shift 2
  "$neuflow" "$@" >"$out/out" 2>"$out/err"
  local got=$?
  [ "$got" -eq "$want" ] || fail "neuflow $*: exit $got, expected $want"
  if [ -n "$pattern" ]; then grep -Eq -- "$pattern" "$out/err" || fail "neuflow $*: stderr lacks /$pattern/"; fi
  echo "ok: neuflow $* -> $got"
}

expect 64 "Subcommands:.*|flow" 
expect 64 "not expected: --bogus" compare --bogus a.flo b.flo
expect 64 "not expected: --modle" flow --modle m.pth a.png b.png out.flo
grep -q "required" "$out/err" && fail "the unknown option must be reported instead of the missing --model"
# No --model, no NEUFLOW_MODEL and no models/neuflow_mixed.pth here: a usage error naming all three.
NEUFLOW_MODEL= expect 64 "no model: give --model CKPT, set NEUFLOW_MODEL" flow a.png b.png out.flo
expect 64 "" no-such-subcommand
expect 64 "nothing to convert" convert -m m.pth -o "$out/o"
expect 64 "expected a multiple of 16" convert -m m.pth -o "$out/o" --model-width 100 --model-height 64 a.mp4
expect 64 "Value -1 not in range|not in range" flow -m m.pth --iters-s8 -1 a.png b.png out.flo
# Each option named once, with its dashes.
expect 64 "^--max-frames: wants 0" convert -m m.pth -o "$out/o" a.mp4 --max-frames -1
[ "$(grep -o -- "--max-frames" "$out/err" | wc -l)" -eq 1 ] || fail "--max-frames named twice"
expect 64 "--model-width and --model-height go together" flow -m m.pth --model-width 32 a.png b.png out.flo
# A bad NEUFLOW_CONV is a configuration error (EX_CONFIG), reported before any work.
NEUFLOW_CONV=wingrad expect 78 "NEUFLOW_CONV: expected auto, direct, winograd, winograd4 or winograd6" flow -m m.pth a.png b.png out.flo
"$neuflow" --help >/dev/null 2>&1 || fail "--help must exit 0"
"$neuflow" flow --help >/dev/null 2>&1 || fail "flow --help must exit 0"
[ "$("$neuflow" --version)" != "" ] || fail "--version prints the version"
echo "all usage checks passed"
