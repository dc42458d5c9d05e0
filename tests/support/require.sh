# Sourced by the shell tests: what a test needs, as the C++ tests treat it. Missing, it is
# skipped (exit 77, ctest's SKIP_RETURN_CODE) unless CI's NEUFLOW_REQUIRE_FIXTURES or
# NEUFLOW_REQUIRE_VULKAN (set, and not 0) makes that a failure.

# The shared fixtures folder: $NEUFLOW_SHARED_DIR/fixtures, else ../shared beside the source tree.
neuflow_fixtures() {
  echo "${NEUFLOW_SHARED_DIR:-$(cd "$(dirname "${BASH_SOURCE[0]}")/../../.." && pwd)/shared}/fixtures"
}

# require_fixture PATH...: each must exist.
require_fixture() {
  local path
  for path in "$@"; do
    [ -e "$path" ] && continue
    echo "fixture not found: $path (set NEUFLOW_SHARED_DIR)"
    if [ -n "${NEUFLOW_REQUIRE_FIXTURES:-}" ] && [ "${NEUFLOW_REQUIRE_FIXTURES}" != 0 ]; then exit 1; fi
    exit 77
  done
}

# require_vulkan NEUFLOW_BINARY: `neuflow devices` lists a device 0.
require_vulkan() {
  "$1" devices | grep -q '^0: ' && return 0
  echo "no Vulkan device here"
  if [ -n "${NEUFLOW_REQUIRE_VULKAN:-}" ] && [ "${NEUFLOW_REQUIRE_VULKAN}" != 0 ]; then exit 1; fi
  exit 77
}
