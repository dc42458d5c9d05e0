#!/usr/bin/env bash
# Builds the libFuzzer harnesses (preset `fuzz`, build/fuzz), writes their seed corpora and
# runs each harness for SECONDS (default 60) on a copy of its seeds, printing one line per
# harness. Exits 1 when a harness found something new (crash, sanitizer report, assertion,
# leak, timeout, out-of-memory); the input is kept under build/fuzz/findings/<harness>/ and
# its path printed. A crash matching a known finding (tests/fuzz/known/<harness>/*/signature)
# is counted and the fuzzer restarted on its grown corpus for the time left.
#
#   bash tests/fuzz/run.sh [SECONDS] [HARNESS...]     e.g. run.sh 600 config
#
# Environment: NEUFLOW_FUZZ_JOBS harnesses at a time (default: the number of CPUs);
# CMAKE_BUILD_PARALLEL_LEVEL compile jobs; NEUFLOW_FUZZ_RSS_MB memory limit per harness
# (default 2048). See tests/fuzz/README.md.
set -uo pipefail

all_harnesses=(flo npy kitti_png checkpoint checkpoint_pickle config config_values ring_reader flow_index retention)
seconds=${1:-60}
(( $# )) && shift
harnesses=("$@")
(( ${#harnesses[@]} )) || harnesses=("${all_harnesses[@]}")
if ! [[ $seconds =~ ^[1-9][0-9]*$ ]]; then
  echo "usage: $0 [SECONDS] [HARNESS...]   (harnesses: ${all_harnesses[*]})" >&2
  exit 2
fi
for h in "${harnesses[@]}"; do
  if [[ " ${all_harnesses[*]} " != *" $h "* ]]; then
    echo "$0: no harness '$h' (harnesses: ${all_harnesses[*]})" >&2
    exit 2
  fi
done

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
cd "$root" || exit 2
build=build/fuzz
findings=$build/findings
known=tests/fuzz/known
jobs=${NEUFLOW_FUZZ_JOBS:-$(nproc)}
rss_mb=${NEUFLOW_FUZZ_RSS_MB:-2048}
max_rounds=100  # restarts after known findings, per harness

# llvm-symbolizer: stacks with function names and lines, which known-finding signatures match.
for tool in clang-14 clang++-14 llvm-symbolizer-14 cmake ninja; do
  if ! command -v "$tool" >/dev/null; then
    echo "$0: $tool not found (Debian: apt install clang-14 libclang-rt-14-dev libomp-14-dev llvm-14 cmake ninja-build)" >&2
    exit 2
  fi
done

work=$(mktemp -d "${TMPDIR:-/tmp}/neuflow-fuzz.XXXXXX") || exit 2
cleanup() {
  local pid
  for pid in $(jobs -p); do kill "$pid" 2>/dev/null; done
  rm -rf "$work"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

step() {  # step NAME COMMAND...: runs it quietly; shows its output when it fails
  local started=$SECONDS
  if ! "${@:2}" >"$work/$1.log" 2>&1; then
    tail -n 60 "$work/$1.log"
    echo "fuzz: $1 failed" >&2
    exit 2
  fi
  echo "fuzz: $1 took $((SECONDS - started)) s"
}
targets=(neuflow_fuzz_seeds)
for h in "${harnesses[@]}"; do targets+=("fuzz_$h"); done
step configure cmake --preset fuzz
step build cmake --build --preset fuzz --target "${targets[@]}"
step seeds "$build/tests/fuzz/neuflow_fuzz_seeds" "$work/seeds"

symbolizer=external_symbolizer_path=$(command -v llvm-symbolizer-14)
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1}:$symbolizer
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}:$symbolizer

# known_finding HARNESS LOG: prints the name of the known finding whose signature LOG matches
# (every non-comment line of known/HARNESS/NAME/signature occurs in it, outside the notes on
# known assertions let through), if one does.
known_finding() {
  local signature line matched report=$2.report
  grep -v '^==FUZZ== known' "$2" >"$report"
  for signature in "$known/$1"/*/signature; do
    [[ -f $signature ]] || continue
    matched=0
    while IFS= read -r line || [[ -n $line ]]; do
      [[ -z $line || $line == '#'* ]] && continue
      grep -qF -- "$line" "$report" || { matched=0; break; }
      matched=1
    done <"$signature"
    if (( matched )); then basename "$(dirname "$signature")"; return 0; fi
  done
  return 1
}

# run_one HARNESS: fuzzes a copy of the seeds for $seconds; restarts after known findings.
# Leaves $work/HARNESS.{result,execs,rss,time,known,notes} for the summary.
run_one() {
  local h=$1 started=$SECONDS deadline=$((SECONDS + seconds)) round=0 left rc log name execs=0 n rss=0 r
  local fuzzer
  local artifacts=$work/artifacts/$h
  mkdir -p "$work/corpus" "$artifacts"
  cp -r "$work/seeds/$h" "$work/corpus/$h"
  : >"$work/$h.known"
  local result=ok
  while left=$((deadline - SECONDS)); (( left > 0 )); do
    if (( ++round > max_rounds )); then
      result="stopped after $max_rounds restarts for known findings"
      break
    fi
    log=$work/$h.$round.log
    "$build/tests/fuzz/fuzz_$h" -max_total_time="$left" -timeout=10 -rss_limit_mb="$rss_mb" \
      -print_final_stats=1 -artifact_prefix="$artifacts/" "$work/corpus/$h" >"$log" 2>&1 &
    fuzzer=$!
    trap 'kill "$fuzzer" 2>/dev/null; exit 143' TERM
    wait "$fuzzer"
    rc=$?
    trap - TERM
    n=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
    execs=$((execs + ${n:-0}))
    r=$(sed -n 's/^stat::peak_rss_mb: *//p' "$log" | tail -n 1)
    (( ${r:-0} > rss )) && rss=$r
    grep -h '^==FUZZ== known' "$log" >>"$work/$h.notes"
    if (( rc == 0 )) && ! compgen -G "$artifacts/[clot]*-*" >/dev/null; then break; fi
    if name=$(known_finding "$h" "$log"); then
      echo "$name" >>"$work/$h.known"
      rm -f "$artifacts"/*
      continue
    fi
    result="found (exit status $rc)"
    mkdir -p "$findings/$h"
    cp "$log" "$findings/$h.log"
    find "$artifacts" -type f -name '*-*' ! -name 'slow-unit-*' -exec cp {} "$findings/$h/" \;
    break
  done
  echo "$result" >"$work/$h.result"
  echo "$execs" >"$work/$h.execs"
  echo "$rss" >"$work/$h.rss"
  echo "$((SECONDS - started))" >"$work/$h.time"
}

rm -rf "$findings"
echo "fuzz: ${#harnesses[@]} harness(es), $seconds s each, $jobs at a time"
started=$SECONDS
for h in "${harnesses[@]}"; do
  while (( $(jobs -rp | wc -l) >= jobs )); do wait -n; done
  run_one "$h" &
done
wait

failed=0
for h in "${harnesses[@]}"; do
  result=$(cat "$work/$h.result" 2>/dev/null || echo "did not finish")
  execs=$(cat "$work/$h.execs" 2>/dev/null || echo 0)
  seeds=$(find "$work/seeds/$h" -type f | wc -l)
  corpus=$(find "$work/corpus/$h" -type f 2>/dev/null | wc -l)
  took=$(cat "$work/$h.time" 2>/dev/null || echo 0)
  line=$(printf '%-24s %9s execs in %3s s (%s/s), corpus %s -> %s, peak RSS %s MB' "fuzz_$h" "$execs" \
         "$took" "$((execs / (took > 0 ? took : 1)))" "$seeds" "$corpus" "$(cat "$work/$h.rss" 2>/dev/null)")
  if [[ $result == ok ]]; then
    echo "ok      $line"
  else
    failed=1
    echo "FAILED  $line: $result"
  fi
  sort "$work/$h.known" 2>/dev/null | uniq -c | while read -r count name; do
    echo "          known finding $name hit $count time(s), restarted (tests/fuzz/known/$h/$name)"
  done
  sort -u "$work/$h.notes" 2>/dev/null | cut -c 10-170 | sed 's/^/          /'
  if [[ -f $findings/$h.log ]]; then
    grep -E '^==FUZZ==|ERROR: (AddressSanitizer|LeakSanitizer|libFuzzer)|runtime error:|SUMMARY:|Assertion|terminate called' \
      "$findings/$h.log" | grep -v '^==FUZZ== known' | head -n 8 | cut -c 1-200 | sed 's/^/          /'
    for input in "$findings/$h"/*; do [[ -f $input ]] && echo "          input: $input"; done
    echo "          log:   $findings/$h.log"
  fi
done
echo "fuzz: fuzzing took $((SECONDS - started)) s"
exit $failed
