#!/usr/bin/env bash
# Checks Basalt's sources the way CI does: clang-format (no diff allowed) and clang-tidy.
#   scripts/lint.sh [BUILD_DIR]      BUILD_DIR holds compile_commands.json (default: build)
#   LINT_FIX=1 scripts/lint.sh       rewrites the files with clang-format instead of failing
#   LINT_TESTS=1 scripts/lint.sh     runs clang-tidy over tests/ too (clang-format always checks them)
#   LINT_JOBS=N scripts/lint.sh      runs N clang-tidy processes (default: one per core)
set -uo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$top/build}
cd "$top"
# Logs go to a folder of this run's own: several checkouts may lint at once on one machine.
logs=$(mktemp -d "${TMPDIR:-/tmp}/basalt-lint.XXXXXX")
mapfile -t sources < <(git ls-files -co --exclude-standard -- '*.cpp' '*.h' | grep -E '^(runtime|devices|media|render|kiosk|sim|app|tools|tests)/')
status=0

if [ "${LINT_FIX:-0}" = 1 ]; then
  clang-format-19 -i "${sources[@]}"
else
  if ! clang-format-19 --dry-run --Werror "${sources[@]}" 2>"$logs/format.log"; then
    echo "lint: these files are not formatted (run LINT_FIX=1 scripts/lint.sh):"
    grep -oE '^[^:]+\.(cpp|h)' "$logs/format.log" | sort -u | sed 's/^/  /'
    status=1
  fi
fi

if [ ! -f "$build/compile_commands.json" ]; then
  echo "lint: $build/compile_commands.json is missing; configure the build first (make build)"
  exit 1
fi
# clang-tidy reads the product's sources; tests/ only with LINT_TESTS=1. Tidying the test suites
# (most of them GoogleTest-heavy) costs more than all of CI's compiling on a 2-core machine, and
# CI has an hour; they are still formatted, built with -Werror and run under the sanitizers.
if [ "${LINT_TESTS:-0}" = 1 ]; then
  mapfile -t units < <(printf '%s\n' "${sources[@]}" | grep '\.cpp$')
else
  mapfile -t units < <(printf '%s\n' "${sources[@]}" | grep '\.cpp$' | grep -v '^tests/')
fi
# Compile commands come from g++; options only g++ knows are ignored by clang.
if ! printf '%s\n' "${units[@]}" | xargs -P "${LINT_JOBS:-$(nproc)}" -n 4 clang-tidy-19 -p "$build" --quiet \
    --extra-arg=-Wno-unknown-warning-option --extra-arg=-Wno-unused-command-line-argument \
    > "$logs/tidy.log" 2>&1; then
  grep -E 'warning:|error:' "$logs/tidy.log" | sort -u | head -50
  echo "lint: clang-tidy found problems (full log: $logs/tidy.log)"
  status=1
fi
if [ $status -eq 0 ]; then
  echo "lint: clean (clang-format, clang-tidy)"
  rm -rf "$logs"
fi
exit $status
