#!/usr/bin/env bash
# The README's first command: install what the build needs, build, and run the main job.
#
# Main job: optical flow between two frames of the sample camera sequence with the published
# NeuFlow-V2 weights (models/neuflow_mixed.pth, or $NEUFLOW_MODEL), written to out/ as a .flo
# file and a colour rendering. Without the weights it renders a benchmark ground-truth flow
# instead and says how to get them.
set -euo pipefail
cd "$(dirname "$0")/.."

bash scripts/install-deps.sh
cmake --preset release
cmake --build --preset release

neuflow=build/release/tools/neuflow
shared="${NEUFLOW_SHARED_DIR:-../shared}"
model="${NEUFLOW_MODEL:-models/neuflow_mixed.pth}"
mkdir -p out

mapfile -t frames < <(ls "$shared"/fixtures/frames/*.jpg 2>/dev/null | sort | head -n 2)
if [ -f "$model" ] && [ ${#frames[@]} -eq 2 ]; then
  "$neuflow" flow --model "$model" "${frames[0]}" "${frames[1]}" out/quickstart.flo --viz out/quickstart.png
  echo "quickstart: flow in out/quickstart.flo, rendering in out/quickstart.png"
elif [ -f "$shared/fixtures/flow-gt/sintel/alley_1_clean_0002/flow.flo" ]; then
  "$neuflow" viz "$shared/fixtures/flow-gt/sintel/alley_1_clean_0002/flow.flo" -o out/quickstart-ground-truth.png --max-flow 20
  echo "quickstart: rendered a Sintel ground-truth flow to out/quickstart-ground-truth.png"
  echo "quickstart: put neuflow_mixed.pth in models/ (see README, 'Getting the model') to compute flow"
else
  echo "quickstart: built; no sample data found at $shared/fixtures and no model at $model" >&2
fi
