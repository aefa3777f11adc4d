#!/usr/bin/env bash
# Line coverage of each fuzz target's parser files (PARSER in tests/fuzz/CMakeLists.txt) over its
# corpus: the replay binaries built with clang-19's source-based coverage
# (-DBASALT_COVERAGE=ON, in build-fuzz-cov/), each run once over the seed corpus
# (tests/fuzz/corpus/<target>/) and once more with what fuzzing added (build-fuzz/corpus/<target>/,
# written by `make fuzz`), read with llvm-profdata-19 and llvm-cov-19 (Debian's llvm-19).
#   scripts/fuzz-coverage.sh [TARGET...]     (default: every target)
# Prints a table: target, seed files, lines covered by the seeds, files fuzzing added, lines
# covered by both, and the parser files' lines. Per-file reports are in build-fuzz-cov/coverage/.
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
build="$top/build-fuzz-cov"
fuzzed="$top/build-fuzz/corpus"
out="$build/coverage"
for tool in clang++-19 llvm-profdata-19 llvm-cov-19; do
  command -v "$tool" >/dev/null || { echo "fuzz-coverage: $tool is missing (scripts/setup.sh --test)"; exit 1; }
done
# Debug: -O0 compiles faster, and the line counts are the source's own.
cmake -S "$top" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Debug -DCMAKE_C_COMPILER=clang-19 \
  -DCMAKE_CXX_COMPILER=clang++-19 -DBASALT_COVERAGE=ON -DBASALT_BENCH=OFF >/dev/null
list="$build/tests/fuzz/fuzz_targets.tsv"
names=("$@")
if [ ${#names[@]} -eq 0 ]; then mapfile -t names < <(cut -f1 "$list"); fi
cmake --build "$build" --target "${names[@]/%/_fuzz_replay}"
rm -rf "$out" && mkdir -p "$out"

# lines BINARY PROFRAW PARSER...: "covered total" lines of the PARSER files.
lines() {
  local binary=$1 raw=$2
  shift 2
  llvm-profdata-19 merge -sparse -o "${raw%.profraw}.profdata" "$raw"
  llvm-cov-19 report "$binary" -instr-profile="${raw%.profraw}.profdata" "$@" >"${raw%.profraw}.txt"
  llvm-cov-19 export -summary-only "$binary" -instr-profile="${raw%.profraw}.profdata" "$@" |
    python3 -c 'import json, sys; t = json.load(sys.stdin)["data"][0]["totals"]["lines"]; print(t["covered"], t["count"])'
}
percent() { awk -v c="$1" -v n="$2" 'BEGIN { printf "%5.1f %%", n ? 100 * c / n : 0 }'; }
count() { { find "$@" -type f 2>/dev/null || true; } | wc -l; }  # 0 for a folder not there

rows=()
status=0
for name in "${names[@]}"; do
  IFS=$'\t' read -r _ corpus parser < <(awk -F'\t' -v n="$name" '$1 == n' "$list")
  [ -n "${corpus:-}" ] || { echo "fuzz-coverage: no target $name"; exit 1; }
  IFS=';' read -r -a files <<<"$parser"
  sources=("${files[@]/#/$top/}")
  binary="$build/tests/fuzz/${name}_fuzz_replay"
  if ! LLVM_PROFILE_FILE="$out/$name.seed.profraw" "$binary" "$corpus" >"$out/$name.seed.log" 2>&1; then
    echo "fuzz-coverage: $name failed on its seed corpus (see $out/$name.seed.log)"
    status=1
    continue
  fi
  read -r seed_covered total < <(lines "$binary" "$out/$name.seed.profraw" "${sources[@]}")
  seeds=$(count "$corpus")
  added=$(count "$fuzzed/$name")
  both="-"
  if [ "$added" -gt 0 ]; then
    if LLVM_PROFILE_FILE="$out/$name.fuzzed.profraw" "$binary" "$corpus" "$fuzzed/$name" >"$out/$name.fuzzed.log" 2>&1; then
      read -r both_covered _ < <(lines "$binary" "$out/$name.fuzzed.profraw" "${sources[@]}")
      both=$(percent "$both_covered" "$total")
    else
      both="replay failed"
      status=1
    fi
  fi
  rows+=("$(printf '%-16s %6s %9s %8s %9s %7s  %s' "$name" "$seeds" "$(percent "$seed_covered" "$total")" "$added" \
    "$both" "$total" "${parser//;/ }")")
done
echo
echo "== fuzz coverage: lines of each target's parser files reached by its corpus"
echo "   (seed: tests/fuzz/corpus/<target>; fuzzed: build-fuzz/corpus/<target>, what make fuzz added)"
printf '%-16s %6s %9s %8s %9s %7s  %s\n' target seeds "lines" fuzzed "lines" "of" "parser files"
printf '%s\n' "${rows[@]}"
echo "(per-file reports: $out/<target>.{seed,fuzzed}.txt)"
exit $status
