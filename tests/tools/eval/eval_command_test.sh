#!/usr/bin/env bash
# `neuflow eval` end to end: the flow-gt fixtures arranged as each benchmark in a scratch
# folder (symbolic links), ground truth copied as predictions (EPE 0), the JSON read back by
# Python, the documented exit codes, and a model run on the fixture checkpoint whose EPE
# against zero ground truth must equal the mean magnitude of the reference flow.
# Usage: eval_command_test.sh NEUFLOW_BINARY PYTHON3_WITH_NUMPY
# Exit 0 = pass, 77 = skipped (fixtures absent and NEUFLOW_REQUIRE_FIXTURES not set).
set -u
neuflow=$1
python=${2:-}
fixtures="${NEUFLOW_SHARED_DIR:-$(dirname "$0")/../../../../shared}/fixtures"
# Absolute, because the layouts below are symbolic links into it.
fixtures=$(cd "$fixtures" 2>/dev/null && pwd) || fixtures=/nonexistent
gt="$fixtures/flow-gt"
seed="$fixtures/neuflow-v2-seed0"
if [[ ! -d "$gt" || ! -f "$seed/checkpoint.pth" ]]; then
  echo "fixtures not found under $fixtures (set NEUFLOW_SHARED_DIR)"
  if [[ -n "${NEUFLOW_REQUIRE_FIXTURES:-}" && "${NEUFLOW_REQUIRE_FIXTURES}" != 0 ]]; then exit 1; fi
  exit 77
fi
if [[ -z "$python" ]] || ! "$python" -c 'import numpy' 2>/dev/null; then
  echo "FAIL: '$python' cannot import numpy (install python3-numpy)"; exit 1
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

# Runs neuflow eval ARGS, keeps stdout/stderr, fails unless the exit status is WANT.
run_expect() {
  local want=$1
  shift
  "$neuflow" eval "$@" >"$work/stdout" 2>"$work/stderr"
  local got=$?
  echo "\$ neuflow eval $*"
  cat "$work/stdout"
  cat "$work/stderr" >&2
  [[ $got -eq $want ]] || fail "exit status $got, expected $want"
}
expect_stdout() { grep -Eq -- "$1" "$work/stdout" || fail "stdout does not match /$1/"; }
expect_stderr() { grep -Eq -- "$1" "$work/stderr" || fail "stderr does not match /$1/"; }
lnk() { mkdir -p "$(dirname "$2")" && ln -s "$1" "$2"; }

# --- layouts -------------------------------------------------------------------------------
S="$work/Sintel/training"
for pass in clean final; do
  lnk "$gt/sintel/alley_1_clean_0002/frame1.png" "$S/$pass/alley_1/frame_0002.png"
  lnk "$gt/sintel/alley_1_clean_0002/frame2.png" "$S/$pass/alley_1/frame_0003.png"
  lnk "$gt/sintel/market_5_final_0009/frame1.png" "$S/$pass/market_5/frame_0009.png"
  lnk "$gt/sintel/market_5_final_0009/frame2.png" "$S/$pass/market_5/frame_0010.png"
done
lnk "$gt/sintel/alley_1_clean_0002/flow.flo" "$S/flow/alley_1/frame_0002.flo"
lnk "$gt/sintel/market_5_final_0009/flow.flo" "$S/flow/market_5/frame_0009.flo"
K="$work/KITTI/training"
lnk "$gt/kitti/frame1.png" "$K/image_2/000000_10.png"
lnk "$gt/kitti/frame2.png" "$K/image_2/000000_11.png"
lnk "$gt/kitti/flow_gt.png" "$K/flow_occ/000000_10.png"
M="$work/middlebury"
for seq in RubberWhale Urban2; do
  for f in frame10.png frame11.png; do lnk "$gt/middlebury/$seq/$f" "$M/other-data/$seq/$f"; done
  lnk "$gt/middlebury/$seq/flow10.flo" "$M/other-gt-flow/$seq/flow10.flo"
done
C="$work/FlyingChairs_release"
lnk "$gt/flyingchairs/0000000-img0.ppm" "$C/data/00001_img1.ppm"
lnk "$gt/flyingchairs/0000000-img1.ppm" "$C/data/00001_img2.ppm"
lnk "$gt/flyingchairs/0000000-gt.flo" "$C/data/00001_flow.flo"

# Ground truth as predictions, named as documented (first image's path, flow extension).
P="$work/pred"
for pass in clean final; do
  lnk "$gt/sintel/alley_1_clean_0002/flow.flo" "$P/sintel/$pass/alley_1/frame_0002.flo"
  lnk "$gt/sintel/market_5_final_0009/flow.flo" "$P/sintel/$pass/market_5/frame_0009.flo"
done
lnk "$gt/kitti/flow_gt.png" "$P/kitti/image_2/000000_10.png"
for seq in RubberWhale Urban2; do lnk "$gt/middlebury/$seq/flow10.flo" "$P/middlebury/other-data/$seq/frame10.flo"; done
lnk "$gt/flyingchairs/0000000-gt.flo" "$P/chairs/00001_img1.flo"

# --- predictions equal to the ground truth: EPE 0 everywhere -------------------------------
run_expect 0 --dataset sintel "$work/Sintel" --predictions "$P/sintel" --per-sequence --json "$work/sintel.json"
expect_stdout '^set +pairs +EPE +<1px +<3px +<5px$'
expect_stdout '^sintel-clean +2 +0\.000 +100\.00% +100\.00% +100\.00%$'
expect_stdout '^sintel-final +2 +0\.000 '
expect_stdout '^  market_5 +1 +0\.000 '
expect_stderr '^eval: sintel-final 2/2 pairs, EPE 0\.000 so far'
"$python" - "$work/sintel.json" <<'PY' || fail "sintel JSON"
import json, sys
d = json.load(open(sys.argv[1]))
assert d["dataset"] == "sintel" and d["source"] == "predictions", d
assert [r["set"] for r in d["results"]] == ["sintel-clean", "sintel-final"]
for r in d["results"]:
    assert r["pairs"] == 2 and r["epe"] == 0 and r["within_1px"] == 1 and r["epe_aggregation"] == "pixels", r
    assert r["valid_pixels"] == 2 * 1024 * 436, r
    assert [s["sequence"] for s in r["sequences"]] == ["alley_1", "market_5"], r
PY

run_expect 0 --dataset kitti "$K" --predictions "$P/kitti" --json -
# NEUFLOW_MODEL names the model for runs that take one; predictions do not conflict with it.
NEUFLOW_MODEL="$work/no-such-model.pth" run_expect 0 --dataset kitti "$K" --predictions "$P/kitti" --json -
"$python" - "$work/stdout" <<'PY' || fail "kitti JSON on stdout"
import json, sys
d = json.load(open(sys.argv[1]))
r = d["results"][0]
assert r["set"] == "kitti" and r["epe"] == 0 and r["fl_all"] == 0 and r["epe_aggregation"] == "images", r
assert 0 < r["valid_pixels"] < 1242 * 375 and "sequences" not in r, r
PY
expect_stderr '^kitti +1 +0\.000 +0\.00% +100\.00%'  # the table moves to stderr with --json -

run_expect 0 --dataset middlebury "$M" --predictions "$P/middlebury" --max-pairs 1
expect_stdout '^middlebury +1 +0\.000 '

# Pictures: one PNG per pair (prediction | ground truth | error, side by side) and an SVG of
# the EPE per sequence.
run_expect 0 --dataset kitti "$K" --predictions "$P/kitti" --save-viz "$work/viz" --plot "$work/epe.svg"
"$python" - "$work/viz" "$work/epe.svg" <<'PY' || fail "--save-viz / --plot output"
import sys, os, struct, xml.etree.ElementTree as ET
viz, svg = sys.argv[1:]
pngs = [os.path.join(d, f) for d, _, fs in os.walk(viz) for f in fs]
assert len(pngs) == 1 and pngs[0].endswith("kitti/image_2/000000_10.png"), pngs
with open(pngs[0], "rb") as f:
    head = f.read(24)
assert head[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
width, height = struct.unpack(">II", head[16:24])
assert (width, height) == (3 * 1242 + 8, 375), (width, height)
root = ET.parse(svg).getroot()
texts = [t.text for t in root.iter("{http://www.w3.org/2000/svg}text")]
assert any(t and t.startswith("kitti: EPE 0.000") for t in texts), texts
assert len(list(root.iter("{http://www.w3.org/2000/svg}rect"))) == 2, "background and one bar"
PY
run_expect 64 --dataset kitti "$K" --predictions "$P/kitti" --plot "$work/epe.png"
run_expect 0 --dataset chairs "$C/data" --predictions "$P/chairs" --pass final
expect_stdout '^chairs +1 +0\.000 '
run_expect 0 --dataset sintel "$work/Sintel/training" --predictions "$P/sintel" --pass final
expect_stdout '^sintel-final +2 '
grep -q "sintel-clean" "$work/stdout" && fail "--pass final evaluated the clean pass"

# --- errors --------------------------------------------------------------------------------
run_expect 66 --dataset kitti "$work/nowhere" --predictions "$P/kitti"
expect_stderr "nowhere: no such dataset folder"
run_expect 66 --dataset sintel "$K" --predictions "$P/sintel"
expect_stderr "not a MPI-Sintel layout: looked for the folders flow/, clean/, final/"
run_expect 66 --dataset middlebury "$M" --predictions "$P/kitti"
expect_stderr "frame10\.\{flo,png,npy\}: no prediction for"
run_expect 66 --dataset kitti "$K" --predictions "$work/no-such-dir"
run_expect 66 --dataset kitti "$K" --model "$work/missing.pth"
mkdir -p "$work/bad/image_2"
printf 'PIEH\x10\x00\x00\x00\x10\x00\x00\x00short' >"$work/bad/image_2/000000_10.flo"
run_expect 65 --dataset kitti "$K" --predictions "$work/bad"
expect_stderr "000000_10\.flo: truncated"
mkdir -p "$work/wrongsize/image_2" && ln -s "$gt/middlebury/Urban2/flow10.flo" "$work/wrongsize/image_2/000000_10.flo"
run_expect 65 --dataset kitti "$K" --predictions "$work/wrongsize"
expect_stderr "is 640x480 but its ground truth"
run_expect 73 --dataset kitti "$K" --predictions "$P/kitti" --json "$work/no/such/dir/out.json"
# Usage errors are CLI11's: neither or both sources, model options without a model.
for args in "--dataset kitti $K" "--dataset kitti $K --predictions $P/kitti --model $seed/checkpoint.pth" \
            "--dataset kitti $K --predictions $P/kitti --iters-s8 2" "--dataset things $K --predictions $P/kitti" \
            "--dataset kitti $K --predictions $P/kitti --max-pairs 0"; do
  # shellcheck disable=SC2086
  "$neuflow" eval $args >/dev/null 2>&1 && fail "accepted: neuflow eval $args"
done
"$neuflow" eval --help | grep -q "mean of the per-image EPEs" || fail "--help does not document the aggregation"

# --- a model run: zero ground truth, so EPE = mean |flow|, against the reference flow ------
Z="$work/seed"
lnk "$seed/frame0.png" "$Z/other-data/seed0/frame10.png"
lnk "$seed/frame1.png" "$Z/other-data/seed0/frame11.png"
mkdir -p "$Z/other-gt-flow/seed0"
"$python" - "$Z/other-gt-flow/seed0/flow10.flo" <<'PY' || fail "writing the zero ground truth"
import struct, sys
with open(sys.argv[1], "wb") as f:
    f.write(struct.pack("<fii", 202021.25, 320, 256) + bytes(8 * 320 * 256))
PY
run_expect 0 --dataset middlebury "$Z" --model "$seed/checkpoint.pth" --threads 2 --json "$work/model.json"
expect_stdout '^middlebury +1 +[0-9]+\.[0-9]{3} '
"$python" - "$work/model.json" "$seed/flow.npy" <<'PY' || fail "the model's EPE is not the reference flow's mean magnitude"
import json, sys
import numpy as np
d = json.load(open(sys.argv[1]))
assert d["source"] == "model" and d["iters_s16"] == 1 and d["iters_s8"] == 8 and d["channel_order"] == "rgb", d
ref = np.load(sys.argv[2])[0].astype(np.float64)  # [2, H, W]
expected = np.sqrt((ref ** 2).sum(axis=0)).mean()
got = d["results"][0]["epe"]
print(f"EPE {got:.6f}, reference mean |flow| {expected:.6f}")
assert abs(got - expected) < 2e-3, (got, expected)
PY
run_expect 0 --dataset middlebury "$Z" --model "$seed/checkpoint.pth" --threads 2 --iters-s8 1 --channel-order bgr --json -
"$python" -c 'import json,sys; d=json.load(open(sys.argv[1])); assert d["channel_order"]=="bgr" and d["iters_s8"]==1, d' \
  "$work/stdout" || fail "model options in the JSON"

# --- convert's flows scored as eval -m scores the model: on KITTI only with --padding bottom ---
# eval pads KITTI at the bottom as the reference does; convert pads centred unless told.
epe_of() { "$python" -c 'import json,sys; print(json.load(open(sys.argv[1]))["results"][0]["epe"])' "$1"; }
run_expect 0 --dataset kitti "$K" --model "$seed/checkpoint.pth" --threads 2 --iters-s8 1 --json "$work/kitti-model.json"
for padding in bottom centred; do
  "$neuflow" convert -m "$seed/checkpoint.pth" --threads 2 --iters-s8 1 --padding "$padding" -o "$work/conv-$padding" \
    "$K/image_2" 2>"$work/stderr" || fail "convert --padding $padding: $(cat "$work/stderr")"
  [[ -f "$work/conv-$padding/image_2/000000_10.flo" ]] || fail "convert wrote no image_2/000000_10.flo"
  run_expect 0 --dataset kitti "$K" --predictions "$work/conv-$padding" --json "$work/kitti-$padding.json"
done
"$python" - "$(epe_of "$work/kitti-model.json")" "$(epe_of "$work/kitti-bottom.json")" \
  "$(epe_of "$work/kitti-centred.json")" <<'PY' || fail "convert --padding bottom does not score as eval -m on KITTI"
import sys
model, bottom, centred = map(float, sys.argv[1:])
print(f"KITTI EPE: eval -m {model:.4f}, convert --padding bottom {bottom:.4f}, centred {centred:.4f}")
assert abs(bottom - model) < 1e-3, (bottom, model)
assert abs(centred - model) > 1e-3, "centred padding scored as bottom: the test cannot tell them apart"
PY
"$neuflow" convert -m "$seed/checkpoint.pth" --padding bottom --model-width 320 --model-height 256 -o "$work/x" \
  "$K/image_2" 2>"$work/stderr"
[[ $? -eq 64 ]] && grep -q "padding bottom pads frames that run at their own size" "$work/stderr" \
  || fail "--padding bottom with a model size must be a usage error: $(cat "$work/stderr")"
grep -q "padding" "$work/conv-bottom/image_2/settings.toml" || fail "the folder's record lacks the padding"
"$neuflow" eval --help | grep -q -- "--padding bottom" || fail "eval --help does not say which padding convert needs"
echo "all eval command checks passed"
