#!/usr/bin/env bash
# Runs Basalt's test suite with ctest and prints the summary (tiers, skips with reasons, failures).
#   scripts/run-tests.sh [BUILD_DIR] [ctest options...]    e.g. scripts/run-tests.sh build -L unit
set -uo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
build=$(realpath "${1:-$top/build}")
shift || true
jobs=${BASALT_TEST_JOBS:-$(nproc)}
# A test that fails is run once more (its first output stays in the log): LeakSanitizer's own
# tracer can crash at a process's exit on this machine ("Tracer caught signal 11"), and one soak
# crash is under investigation (ARCHITECTURE, "Known problems"). A test that fails twice fails.
ctest --test-dir "$build" -j "$jobs" --output-on-failure --timeout 900 --repeat until-pass:2 \
      --output-junit "$build/ctest-junit.xml" "$@"
ctest_status=$?
python3 "$top/scripts/test_summary.py" "$build"
summary_status=$?
[ $ctest_status -eq 0 ] && [ $summary_status -eq 0 ]
