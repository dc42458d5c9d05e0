#!/usr/bin/env bash
# `neuflow flow` on the fixture checkpoint and frames reproduces the reference's final flow,
# in each output format, and fails with the documented exit codes on bad input.
# Usage: flow_command_test.sh NEUFLOW_BINARY PYTHON_WITH_NUMPY
set -u
neuflow=$1
python=$2
source "$(dirname "$0")/../support/require.sh"
fixture="$(neuflow_fixtures)/neuflow-v2-seed0"
require_fixture "$fixture/checkpoint.pth"
if ! "$python" -c 'import numpy' 2>/dev/null; then
  echo "$python cannot import numpy (install python3-numpy)"; exit 1
fi
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

"$neuflow" flow --threads 2 -m "$fixture/checkpoint.pth" "$fixture/frame0.png" "$fixture/frame1.png" \
  "$out/flow.npy" --viz "$out/viz.png" || fail "neuflow flow exited $?"
[ -s "$out/viz.png" ] || fail "no visualization written"
"$python" - "$out/flow.npy" "$fixture/flow.npy" <<'PY' || fail "flow differs from the reference"
import sys, numpy as np
ours = np.load(sys.argv[1])
ref = np.load(sys.argv[2])[0].transpose(1, 2, 0)
assert ours.shape == (256, 320, 2), ours.shape
err = np.abs(ours - ref)
print(f"max error {err.max():.2e} px, mean {err.mean():.2e} px")
assert err.max() < 1e-2 and err.mean() < 1e-3
PY

"$neuflow" flow -m "$fixture/checkpoint.pth" "$fixture/frame0.png" "$fixture/frame1.png" "$out/flow.flo" --iters-s8 1 \
  || fail ".flo output"
"$neuflow" compare "$out/flow.flo" "$out/flow.flo" | grep -q "EPE" || fail "compare cannot read our .flo"

"$neuflow" flow -m "$out/missing.pth" "$fixture/frame0.png" "$fixture/frame1.png" "$out/x.flo"
[ $? -eq 66 ] || fail "a missing checkpoint must exit 66"
"$neuflow" flow -m "$fixture/frame0.png" "$fixture/frame0.png" "$fixture/frame1.png" "$out/x.flo"
[ $? -eq 65 ] || fail "a non-checkpoint must exit 65"
"$neuflow" flow -m "$fixture/checkpoint.pth" "$fixture/manifest.json" "$fixture/frame1.png" "$out/x.flo"
[ $? -eq 65 ] || fail "a non-image must exit 65"
"$neuflow" flow -m "$fixture/checkpoint.pth" "$fixture/frame0.png" "$fixture/frame1.png" "$out/x.txt"
[ $? -ne 0 ] || fail "an unknown output extension must fail"
"$neuflow" flow -m "$fixture/checkpoint.pth" "$fixture/frame0.png" "$fixture/frame1.png" "$out/no/such/dir/x.flo"
[ $? -eq 73 ] || fail "an unwritable output must exit 73"
# The model options have the element's names; --size and --bgr are the earlier spellings,
# kept hidden: each pair must give the same flow, and the help shows only the new names.
run_pair() {  # run_pair OUT OPTIONS...
  local result=$1; shift
  "$neuflow" flow --threads 2 --iters-s8 1 -m "$fixture/checkpoint.pth" "$fixture/frame0.png" "$fixture/frame1.png" \
    "$result" "$@" || fail "neuflow flow $* exited $?"
}
run_pair "$out/named.npy" --model-width 160 --model-height 128 --channel-order bgr
run_pair "$out/alias.npy" --size 160x128 --bgr
run_pair "$out/rgb.npy" --model-width 160 --model-height 128
"$python" - "$out/named.npy" "$out/alias.npy" "$out/rgb.npy" <<'PY' || fail "the old spellings differ from the new names"
import sys, numpy as np
named, alias, rgb = (np.load(p) for p in sys.argv[1:])
assert named.shape == (256, 320, 2), named.shape
assert np.array_equal(named, alias), "--size/--bgr must equal --model-width/--model-height/--channel-order"
assert not np.array_equal(named, rgb), "--channel-order bgr must change what the network sees"
PY
"$neuflow" flow --help | grep -q -- "--model-width" || fail "help must list --model-width"
if "$neuflow" flow --help | grep -q -- "--size"; then fail "help must not list the hidden --size"; fi
"$neuflow" flow -m "$fixture/checkpoint.pth" --model-width 100 --model-height 64 \
  "$fixture/frame0.png" "$fixture/frame1.png" "$out/x.flo" 2>"$out/err"
[ $? -eq 64 ] || fail "a model width that is not a multiple of 16 is a usage error (64)"
grep -q "model-width: expected a multiple of 16" "$out/err" || fail "unclear model-width error: $(cat "$out/err")"
"$neuflow" flow -m "$fixture/checkpoint.pth" --size 160 "$fixture/frame0.png" "$fixture/frame1.png" "$out/x.flo" \
  2>"$out/err"
[ $? -eq 64 ] && grep -q "WIDTHxHEIGHT" "$out/err" || fail "--size without a height must say WIDTHxHEIGHT"
# A frame size whose plan needs more than --max-memory is refused before the plan is made.
"$neuflow" flow --max-memory 1 -m "$fixture/checkpoint.pth" "$fixture/frame0.png" "$fixture/frame1.png" "$out/x.flo" \
  2>"$out/err"
[ $? -ne 0 ] || fail "a plan over --max-memory ran"
grep -q "a 320x256 model size needs about .*, more than the 1 MiB max-memory allows" "$out/err" \
  || fail "unclear max-memory error: $(cat "$out/err")"
# An image is refused by the size its header states, before it is decoded: a 3 KB PNG that
# says 20000x20000 (1.2 GB decoded) is past the supported range, and one that says 4000x3000 is
# past a small --max-memory; neither takes the memory its decoding would.
"$python" - "$out" "$neuflow" "$fixture/checkpoint.pth" <<'PY' || fail "a PNG's header size was not refused before decoding"
import resource, struct, subprocess, sys, zlib
out, neuflow, checkpoint = sys.argv[1:4]
def png(path, width, height):  # a valid header and a few rows of data, no more
    chunk = lambda t, d: struct.pack('>I', len(d)) + t + d + struct.pack('>I', zlib.crc32(t + d))
    rows = zlib.compress((b'\0' + b'\0' * width * 3) * 8, 9)
    with open(path, 'wb') as f:
        f.write(b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', width, height, 8, 2, 0, 0, 0))
                + chunk(b'IDAT', rows) + chunk(b'IEND', b''))
png(f'{out}/huge.png', 20000, 20000)
png(f'{out}/large.png', 4000, 3000)
for image, options, says in [('huge.png', [], 'outside the supported range'),
                             ('large.png', ['--max-memory', '64'], 'more than the 64 MiB max-memory allows')]:
    r = subprocess.run([neuflow, 'flow', '-m', checkpoint, *options, f'{out}/{image}', f'{out}/{image}',
                        f'{out}/x.flo'], capture_output=True, text=True)
    assert r.returncode == 65, (image, r.returncode, r.stderr)
    assert 'its header says' in r.stderr and 'not decoded' in r.stderr and says in r.stderr, r.stderr
rss_mb = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
print(f'largest resident size of the refused runs: {rss_mb:.0f} MB')
assert rss_mb < 500, rss_mb
PY

# Without --model: $NEUFLOW_MODEL, else models/neuflow_mixed.pth in the working folder, each said
# on stderr; with neither, a usage error naming all three.
frames=("$(cd "$fixture" && pwd)/frame0.png" "$(cd "$fixture" && pwd)/frame1.png")
checkpoint=$(cd "$fixture" && pwd)/checkpoint.pth
mkdir -p "$out/cwd/models"
(cd "$out/cwd" && env -u NEUFLOW_MODEL "$neuflow" flow --iters-s8 1 "${frames[@]}" "$out/x.flo" 2>"$out/err")
[ $? -eq 64 ] || fail "no model anywhere must exit 64"
grep -q -- "give --model CKPT, set NEUFLOW_MODEL, or run \`neuflow fetch-model mixed\`" "$out/err" \
  || fail "unclear missing-model error: $(cat "$out/err")"
(cd "$out/cwd" && NEUFLOW_MODEL="$checkpoint" "$neuflow" flow --iters-s8 1 "${frames[@]}" "$out/env.flo" \
  2>"$out/err") || fail "NEUFLOW_MODEL was not taken: $(cat "$out/err")"
grep -q "(from NEUFLOW_MODEL)" "$out/err" || fail "NEUFLOW_MODEL taken silently: $(cat "$out/err")"
ln -s "$checkpoint" "$out/cwd/models/neuflow_mixed.pth"
(cd "$out/cwd" && env -u NEUFLOW_MODEL "$neuflow" flow --iters-s8 1 "${frames[@]}" "$out/default.flo" \
  2>"$out/err") || fail "models/neuflow_mixed.pth was not taken: $(cat "$out/err")"
grep -q "model models/neuflow_mixed.pth (no --model or NEUFLOW_MODEL given)" "$out/err" \
  || fail "the default model taken silently: $(cat "$out/err")"
cmp -s "$out/env.flo" "$out/default.flo" || fail "the same checkpoint by two routes gave two flows"
echo "all flow command checks passed"
