#!/usr/bin/env bash
# A file pipeline with backend=vulkan (multifilesrc ! pngdec ! videoconvert ! neuflow !
# neuflowsink, the element keeping a frame in flight while the next one goes up) writes the
# flows that `neuflow convert --backend vulkan` writes for the same frames: the same pairs, in
# the same order, equal within 1e-4 px (the same device, shaders and pixels). Both run under the
# Khronos validation layer, fatal on any message.
# Usage: vulkan_pipeline_matches_cli_test.sh NEUFLOW GST_LAUNCH PYTHON3
set -u
neuflow=$1
launch=$2
python=$3
source "$(dirname "$0")/../support/require.sh"
fixture="$(neuflow_fixtures)/neuflow-v2-seed0"
require_fixture "$fixture/checkpoint.pth"
require_vulkan "$neuflow"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
export NEUFLOW_VULKAN_VALIDATION=fatal
model="$fixture/checkpoint.pth"
frames=5

# Moving colour bars, so that every pair has motion and texture everywhere.
mkdir -p "$out/frames" "$out/gst"
"$launch" -q videotestsrc num-buffers=$frames pattern=smpte horizontal-speed=3 \
  ! video/x-raw,format=RGB,width=96,height=64,framerate=10/1 ! pngenc ! multifilesink location="$out/frames/%05d.png" \
  || fail "could not write the test frames"

"$neuflow" convert -m "$model" -o "$out/cli" --backend vulkan --device 0 --iters-s8 2 --threads 2 "$out/frames" \
  || fail "neuflow convert --backend vulkan failed"

"$launch" multifilesrc location="$out/frames/%05d.png" index=0 stop-index=$((frames - 1)) caps=image/png,framerate=10/1 \
  ! pngdec ! videoconvert ! neuflow name=nf backend=vulkan device=0 iters-s8=2 threads=2 behaviour=every-pair \
    model="$model" ! neuflowsink location="$out/gst/%05d.flo" > "$out/launch.log" 2>&1
status=$?
cat "$out/launch.log"
[ "$status" -eq 0 ] || fail "the pipeline failed (exit $status)"
grep -q "Got EOS" "$out/launch.log" || fail "the pipeline did not reach EOS"

# Both index.csv files name each flow file and the two frames it is between (frames counted
# from 0 by both).
"$python" - "$out/cli/frames" "$out/gst" $((frames - 1)) <<'EOF' || fail "the flows differ"
import array, csv, os, struct, sys

cli_dir, gst_dir, pairs = sys.argv[1], sys.argv[2], int(sys.argv[3])

def read_flo(path):
    with open(path, "rb") as f:
        magic, width, height = struct.unpack("<fii", f.read(12))
        if magic != 202021.25:
            sys.exit(f"{path}: not a .flo file")
        uv = array.array("f")
        uv.frombytes(f.read())
    if len(uv) != 2 * width * height:
        sys.exit(f"{path}: {len(uv)} values, expected {2 * width * height}")
    return width, height, uv

def pairs_of(folder):
    with open(os.path.join(folder, "index.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    if len(rows) != pairs:
        sys.exit(f"{folder}/index.csv: {len(rows)} flows, expected {pairs}")
    for i, row in enumerate(rows):
        if (int(row["from_frame"]), int(row["to_frame"])) != (i, i + 1):
            sys.exit(f"{folder}/index.csv: row {i} is the pair {row['from_frame']} -> {row['to_frame']}")
    return [os.path.join(folder, row["file"]) for row in rows]

worst = 0.0
for i, (cli_path, gst_path) in enumerate(zip(pairs_of(cli_dir), pairs_of(gst_dir))):
    w0, h0, a = read_flo(cli_path)
    w1, h1, b = read_flo(gst_path)
    if (w0, h0) != (w1, h1):
        sys.exit(f"{gst_path} is {w1}x{h1}, {cli_path} {w0}x{h0}")
    diff = max(abs(x - y) for x, y in zip(a, b))
    magnitude = max(abs(x) for x in a)
    print(f"pair {i}: {os.path.basename(cli_path)} vs {os.path.basename(gst_path)}: "
          f"max difference {diff:.3g} px (largest component {magnitude:.3g} px)")
    worst = max(worst, diff)
if worst > 1e-4:
    sys.exit(f"largest difference {worst:.3g} px > 1e-4 px")
EOF
echo "ok"
