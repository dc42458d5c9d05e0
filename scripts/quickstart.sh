#!/usr/bin/env bash
# The README's first command: install what the build needs, build, and run the main job.
#
# Main job: a real video — OpenCV's sample vtest.avi (Debian package opencv-doc, 768x576) — to
# optical flow with the published NeuFlow-V2 weights: one .flo file per consecutive pair of
# its first $NEUFLOW_QUICKSTART_FRAMES frames (default 30), index.csv, and the colour
# rendering as an H.264 MP4, all under out/vtest/.
#
# The weights: models/neuflow_mixed.pth (or $NEUFLOW_MODEL); fetched from the official
# repository when absent. On a machine without network access and without the file, the job
# runs with the test checkpoint from ../shared (random weights) so that the whole path is
# still exercised — and says loudly that its flow is meaningless.
set -euo pipefail
cd "$(dirname "$0")/.."

bash scripts/install-deps.sh
cmake --preset release
cmake --build --preset release

neuflow=build/release/tools/neuflow
shared="${NEUFLOW_SHARED_DIR:-../shared}"
model="${NEUFLOW_MODEL:-models/neuflow_mixed.pth}"
video=/usr/share/doc/opencv-doc/examples/data/vtest.avi
frames="${NEUFLOW_QUICKSTART_FRAMES:-30}"

random_weights=""
if [ ! -f "$model" ]; then
  if ! "$neuflow" fetch-model mixed --output-dir "$(dirname "$model")"; then
    fallback="$shared/fixtures/neuflow-v2-seed0/checkpoint.pth"
    if [ ! -f "$fallback" ]; then
      echo "quickstart: no weights at $model and no download possible; put neuflow_mixed.pth there (README, 'Getting the model')" >&2
      exit 1
    fi
    random_weights=1
    model="$fallback"
    echo "quickstart: WARNING: could not fetch neuflow_mixed.pth; running with the RANDOM-WEIGHT test checkpoint" >&2
    echo "quickstart: WARNING: the output shows the pipeline working, not real motion" >&2
  fi
fi

rm -rf out/vtest
"$neuflow" convert --model "$model" --output out --format flo --viz video --max-frames "$frames" "$video"
echo "quickstart: $(ls out/vtest/*.flo | wc -l) flow files, out/vtest/index.csv and the rendering out/vtest/viz.mp4"
if [ -n "$random_weights" ]; then
  echo "quickstart: (computed with random weights — fetch the published model and run again for real flow)"
fi
