#!/usr/bin/env bash
# Checks that every tracked C and C++ file is formatted as .clang-format says (clang-format-14,
# Debian 12's), and names each file that is not. CI's first step: it needs no build.
#   bash scripts/check-format.sh          # check
#   bash scripts/check-format.sh --fix    # rewrite the files in place
set -euo pipefail
cd "$(dirname "$0")/.."
formatter=${CLANG_FORMAT:-clang-format-14}
if ! command -v "$formatter" > /dev/null; then
  echo "check-format: $formatter not found (Debian: apt install clang-format-14, or bash scripts/install-deps.sh)" >&2
  exit 1
fi
# The params headers are GLSL as much as C++ (shaders/params/interface.h): their macros are
# not statements clang-format understands.
mapfile -t files < <(git ls-files '*.c' '*.cpp' '*.h' '*.hpp' | grep -v '^model/src/vulkan/shaders/params/')
if [ "${1:-}" = "--fix" ]; then
  "$formatter" -i "${files[@]}"
  exit 0
fi
bad=()
for f in "${files[@]}"; do
  "$formatter" --dry-run -Werror "$f" > /dev/null 2>&1 || bad+=("$f")
done
if [ ${#bad[@]} -gt 0 ]; then
  printf 'check-format: not formatted as .clang-format says: %s\n' "${bad[@]}" >&2
  echo "check-format: ${#bad[@]} of ${#files[@]} files; fix with: bash scripts/check-format.sh --fix" >&2
  exit 1
fi
echo "check-format: ${#files[@]} files formatted"
