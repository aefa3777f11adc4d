#!/usr/bin/env bash
# Builds Basalt's libFuzzer targets with clang-19 (ASan + UBSan, every Basalt library with
# libFuzzer's coverage instrumentation) and runs each for a bounded time.
#   scripts/fuzz.sh [SECONDS_PER_TARGET]    (default 60; CI uses a shorter budget)
# FUZZ_ONLY="a b" fuzzes only those targets; FUZZ_SKIP="a b" skips targets with an open finding.
# Before fuzzing, fuzz_instrumented.* checks that every library a target links is instrumented.
# At the end a table gives, per target, the runs and libFuzzer's final cov: (coverage points,
# edges) and ft: (features) figures; each run's full output is in build-fuzz/logs/<target>.log.
# New crashes are written to build-fuzz/crashes/<target>/; add them to tests/fuzz/corpus/<target>/
# once fixed, so that the gcc replay test keeps them fixed. What fuzzing adds to a corpus stays in
# build-fuzz/corpus/<target>/, where the next run (and `make fuzz-coverage`) starts from it.
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
seconds=${1:-60}
build="$top/build-fuzz"
cmake -S "$top" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang-19 \
  -DCMAKE_CXX_COMPILER=clang++-19 -DBASALT_FUZZ=ON -DBASALT_SANITIZE=address,undefined >/dev/null
mapfile -t fuzzers < <(cd "$build" && ninja -t targets all | grep -oE '^[a-z0-9_]+_fuzzer:' | tr -d : | grep -v '^cmake_' | sort -u)
if [ -n "${FUZZ_ONLY:-}" ]; then
  mapfile -t fuzzers < <(for f in "${fuzzers[@]}"; do [[ " $FUZZ_ONLY " == *" ${f%_fuzzer} "* ]] && echo "$f"; done)
fi
if [ ${#fuzzers[@]} -eq 0 ]; then
  echo "fuzz: no fuzz targets defined${FUZZ_ONLY:+ among FUZZ_ONLY=\"$FUZZ_ONLY\"}"
  exit 0
fi
cmake --build "$build" --target "${fuzzers[@]}"
checks=$(printf '%s\n' "${fuzzers[@]}" | sed 's/_fuzzer$//' | paste -sd'|')
if ! ctest --test-dir "$build" -R "^fuzz_instrumented\\.($checks)\$" --output-on-failure >"$build/instrumented.log" 2>&1; then
  cat "$build/instrumented.log"
  echo "fuzz: a library under test lacks the coverage instrumentation (fuzz_instrumented.*)"
  exit 1
fi
echo "== fuzz: every Basalt library the targets link is instrumented ($(grep -c ' Passed ' "$build/instrumented.log") checks)"
mkdir -p "$build/logs"
summary=()
status=0
for f in "${fuzzers[@]}"; do
  name=${f%_fuzzer}
  # FUZZ_SKIP="a b": targets with a known, open finding (ARCHITECTURE "Known problems").
  if [[ " ${FUZZ_SKIP:-} " == *" $name "* ]]; then
    echo "== fuzz: $name skipped (FUZZ_SKIP: a known finding is open)"
    summary+=("$(printf '%-16s %9s %7s %7s %7s  %s' "$name" - - - - "skipped (FUZZ_SKIP)")")
    continue
  fi
  corpus="$top/tests/fuzz/corpus/$name"
  work="$build/corpus/$name"
  crashes="$build/crashes/$name"
  log="$build/logs/$name.log"
  mkdir -p "$work" "$crashes"
  echo "== fuzz: $name for ${seconds}s"
  result=ok
  if ! (cd "$crashes" && UBSAN_OPTIONS=halt_on_error=1 "$build/tests/fuzz/$f" -max_total_time="$seconds" \
        -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 "$work" "$corpus" >"$log" 2>&1); then
    result="FOUND A PROBLEM: see $crashes"
    status=1
  fi
  tail -20 "$log"
  [ "$result" = ok ] || echo "fuzz: $name found a problem; see $crashes"
  # libFuzzer's last status line: "#RUNS DONE cov: N ft: N corp: UNITS/SIZE ..." (or the line
  # before a crash).
  last=$(grep -E '^#[0-9]+.* cov: [0-9]+ ft: [0-9]+' "$log" | tail -1 || true)
  runs=$(sed -nE 's/^#([0-9]+).*/\1/p' <<<"$last")
  cov=$(sed -nE 's/.* cov: ([0-9]+).*/\1/p' <<<"$last")
  ft=$(sed -nE 's/.* ft: ([0-9]+).*/\1/p' <<<"$last")
  corp=$(sed -nE 's/.* corp: ([0-9]+).*/\1/p' <<<"$last")
  summary+=("$(printf '%-16s %9s %7s %7s %7s  %s' "$name" "${runs:--}" "${cov:--}" "${ft:--}" "${corp:--}" "$result")")
done
echo
echo "== fuzz summary: ${seconds}s per target; cov: coverage points (edges) reached, ft: features, corpus: units kept"
printf '%-16s %9s %7s %7s %7s  %s\n' target runs cov ft corpus result
printf '%s\n' "${summary[@]}"
exit $status
