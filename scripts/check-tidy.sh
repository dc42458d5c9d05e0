#!/usr/bin/env bash
# clang-tidy-14 with .clang-tidy's checks on C++ sources, against a configured build's
# compile_commands.json (default build/release). A finding fails it.
#   bash scripts/check-tidy.sh              # the .cpp files changed since $NEUFLOW_TIDY_BASE, and
#                                           # the .cpp twins of changed headers; the default base is
#                                           # the newest commit three hours older than HEAD (a
#                                           # submission's commits, made in one session of at most
#                                           # three hours: CI runs on a clone of main, with no branch)
#   NEUFLOW_TIDY_PART=sources|tests         # with the default: only the changed files outside tests/,
#                                           # or only those in it (CI's first stage takes the sources)
#   bash scripts/check-tidy.sh --all        # every .cpp file (about 10 s a file on 2 cores)
#   bash scripts/check-tidy.sh FILE...      # these files
set -euo pipefail
cd "$(dirname "$0")/.."
build=${NEUFLOW_TIDY_BUILD:-build/release}
tidy=${CLANG_TIDY:-clang-tidy-14}
if ! command -v "$tidy" > /dev/null; then
  echo "check-tidy: $tidy not found (Debian: apt install clang-tidy-14, or bash scripts/install-deps.sh)" >&2
  exit 1
fi
if [ ! -f "$build/compile_commands.json" ]; then
  echo "check-tidy: no $build/compile_commands.json: configure first (cmake --preset release)" >&2
  exit 1
fi
if [ "${1:-}" = "--all" ]; then
  mapfile -t files < <(git ls-files '*.cpp')
elif [ $# -gt 0 ]; then
  files=("$@")
else
  base=${NEUFLOW_TIDY_BASE:-$(git rev-list -1 --before=$(( $(git log -1 --format=%ct) - 3 * 3600 )) HEAD)}
  if ! git rev-parse -q --verify "$base^{commit}" > /dev/null; then
    echo "check-tidy: base $base not found (a shallow clone?): checking nothing" >&2
    exit 0
  fi
  mapfile -t changed < <(git diff --name-only --diff-filter=d "$base" -- '*.cpp' '*.hpp')
  files=()
  for f in "${changed[@]}"; do
    # A file whose change is only clang-format's (its old text formatted is its new text) is
    # check-format's business, not a change to tidy.
    if git cat-file -e "$base:$f" 2> /dev/null &&
      git show "$base:$f" | clang-format-14 --assume-filename="$f" | cmp -s - "$f"; then
      continue
    fi
    [ "${f%.hpp}" != "$f" ] && f="${f%.hpp}.cpp"
    case "${NEUFLOW_TIDY_PART:-all}:$f" in
      sources:tests/*) continue ;;
      tests:tests/*) ;;
      tests:*) continue ;;
    esac
    [ -f "$f" ] && files+=("$f")
  done
fi
# Only files the build compiles have a command line to check them with.
mapfile -t files < <(printf '%s\n' "${files[@]}" | sort -u | while read -r f; do
  [ -n "$f" ] && grep -q "\"file\": \"$(pwd)/$f\"" "$build/compile_commands.json" && echo "$f"; done)
if [ ${#files[@]} -eq 0 ]; then
  echo "check-tidy: no compiled .cpp file changed"
  exit 0
fi
echo "check-tidy: ${#files[@]} files: ${files[*]}"
# The build's -Werror and GCC-only warning options are not clang-tidy's business.
printf '%s\n' "${files[@]}" | xargs -P 2 -n 4 "$tidy" -p "$build" --quiet \
  --extra-arg=-Wno-error --extra-arg=-Wno-unknown-warning-option 2> /tmp/check-tidy.$$ || {
  grep -v "warnings generated\|^Suppressed\|^Use -header-filter" /tmp/check-tidy.$$ >&2 || true
  rm -f /tmp/check-tidy.$$
  echo "check-tidy: findings above (.clang-tidy's checks)" >&2
  exit 1
}
rm -f /tmp/check-tidy.$$
echo "check-tidy: no findings"
