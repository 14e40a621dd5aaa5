#!/usr/bin/env bash
# tools/ci_times.sh BUILD_DIR [N]: where a build's time went: the N (20) slowest objects to compile
# (Ninja's log, BUILD_DIR/.ninja_log: the last build of each output) and the N slowest tests of the
# last ctest run (BUILD_DIR/Testing/Temporary/CTestCostData.txt: each test's average seconds).
# Printed by .ci/run after each stage; nothing is asserted here.
set -eu  # no pipefail: `sort | head` ends sort early (SIGPIPE), which is no failure of the report
build="${1:?usage: tools/ci_times.sh BUILD_DIR [N]}"
n="${2:-20}"
if [[ -f "$build/.ninja_log" ]]; then
  echo "  slowest $n objects to compile (s):"
  # .ninja_log v5: start_ms end_ms mtime output hash; a later line for an output replaces the earlier
  awk 'NR > 1 && !/^#/ { t[$4] = ($2 - $1) / 1000 } END { for (o in t) printf "%8.1f  %s\n", t[o], o }' "$build/.ninja_log" |
    sort -rn | head -n "$n" | sed 's/^/  /'
  awk 'NR > 1 && !/^#/ { t[$4] = ($2 - $1) / 1000 } END { s = 0; for (o in t) s += t[o]; printf "  all %d outputs: %.0f s of compiling and linking (over the cores)\n", length(t), s }' "$build/.ninja_log"
fi
cost="$build/Testing/Temporary/CTestCostData.txt"
if [[ -f "$cost" ]]; then
  echo "  slowest $n tests (s):"
  # lines "name runs average_seconds" until the "---" that starts the list of failures
  awk '/^---/ { exit } NF == 3 { printf "%8.2f  %s\n", $3, $1 }' "$cost" | sort -rn | head -n "$n" | sed 's/^/  /'
  awk '/^---/ { exit } NF == 3 { s += $3; k++ } END { printf "  all %d tests: %.0f s (over the cores)\n", k, s }' "$cost"
fi
