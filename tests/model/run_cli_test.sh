#!/bin/sh
# Runs one `neuflow` command line for ctest and checks its exit status and output.
#
#   run_cli_test.sh SHARED_DIR FIXTURE EXPECTED_STATUS EXPECTED_TEXT COMMAND [ARGS...]
#
# FIXTURE is a path under <shared>/fixtures ("-" for none), where <shared> is
# $NEUFLOW_SHARED_DIR if set, else SHARED_DIR; an argument spelled @FIXTURE@ is replaced by its
# full path. A missing fixture skips the test (exit 77, ctest's SKIP_RETURN_CODE) unless
# NEUFLOW_REQUIRE_FIXTURES is set to something other than 0, which makes it a failure.
# EXPECTED_TEXT ("" for none) must occur in stdout+stderr.
set -u
shared_default=$1
fixture=$2
expect_status=$3
expect_text=$4
shift 4

shared=${NEUFLOW_SHARED_DIR:-$shared_default}
fixture_path=""
if [ "$fixture" != "-" ]; then
  fixture_path="$shared/fixtures/$fixture"
  if [ ! -e "$fixture_path" ]; then
    case "${NEUFLOW_REQUIRE_FIXTURES:-}" in
      "" | 0)
        echo "SKIP: fixture '$fixture_path' not found (set NEUFLOW_SHARED_DIR)"
        exit 77
        ;;
      *)
        echo "FAIL: fixture '$fixture_path' not found and NEUFLOW_REQUIRE_FIXTURES is set"
        exit 1
        ;;
    esac
  fi
fi

# Substitute @FIXTURE@ in the command line.
count=$#
i=0
while [ "$i" -lt "$count" ]; do
  arg=$1
  shift
  if [ "$arg" = "@FIXTURE@" ]; then arg=$fixture_path; fi
  set -- "$@" "$arg"
  i=$((i + 1))
done

output=$("$@" 2>&1)
status=$?
printf '%s\n' "$output"
if [ "$status" -ne "$expect_status" ]; then
  echo "FAIL: exit status $status, expected $expect_status"
  exit 1
fi
if [ -n "$expect_text" ]; then
  case "$output" in
    *"$expect_text"*) ;;
    *)
      echo "FAIL: the output lacks '$expect_text'"
      exit 1
      ;;
  esac
fi
echo "PASS"
