#!/usr/bin/env bash
# tools/fuzz.sh [SECONDS]: installs clang and libFuzzer, builds the fuzz targets (ASan + UBSan,
# assertions on) in the instrumented build, build-asan/ (or $KDL_SPACE_ASAN_BUILD_DIR), and runs
# each for SECONDS (default 60) on a scratch copy of its seed corpus fuzz/corpus/<target>/ (the repository
# is never written). Fails on any finding (crash, sanitizer report, leak, uncaught exception,
# timeout of one input, memory blow-up) and prints the path of the input that caused it; see
# README "Sanitizers and fuzzing" for turning it into a regression test.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
seconds="${1:-60}"
[[ "$seconds" =~ ^[0-9]+$ ]] && ((seconds > 0)) || { echo "usage: tools/fuzz.sh [SECONDS]" >&2; exit 2; }

# The fuzz targets of the one instrumented build (tools/sanitized_build.sh: after tools/sanitize.sh,
# already built).
source "$root/tools/sanitized_build.sh"
sanitized_build fuzz_urdf fuzz_scenario fuzz_study fuzz_commands fuzz_page

export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1${UBSAN_OPTIONS:+:$UBSAN_OPTIONS}"
export LSAN_OPTIONS="suppressions=$root/tools/sanitizers/lsan.supp:print_suppressions=0${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
work="$(mktemp -d "${TMPDIR:-/tmp}/kdl_space_fuzz.XXXXXX")"
trap 'rm -rf "$work"' EXIT
artifacts="$build/artifacts"
failed=0
# One target for SECONDS, then its verdict: `fuzz_one NAME MAX_LEN DICT` (exit 1 on a finding).
fuzz_one() {
  local name="$1" max_len="$2" dict="$3" rc=0
  local target="fuzz_$name" log="$build/fuzz_$name.log"
  mkdir -p "$work/$name" "$artifacts/$name"
  cp "$root/fuzz/corpus/$name/"* "$work/$name/"
  # The inputs that once found a bug are seeds too (tests/data/fuzz_regressions/, if any).
  cp "$root/tests/data/fuzz_regressions/$name/"* "$work/$name/" 2>/dev/null || true
  # -timeout: one input taking longer than 10 s is a hang (a finding); -rss_limit_mb: a blow-up.
  "$build/fuzz/$target" "$work/$name" -dict="$root/fuzz/$dict.dict" \
    -max_total_time="$seconds" -max_len="$max_len" -timeout=10 -rss_limit_mb=2048 \
    -artifact_prefix="$artifacts/$name/" -print_final_stats=1 >"$log" 2>&1 || rc=$?
  {
    if ((rc == 0)); then
      echo "tools/fuzz.sh: $target ran ${seconds} s (log: $log)"
      grep -E "^stat::(number_of_executed_units|new_units_added|peak_rss_mb)|#[0-9]+.*DONE" "$log" | sed 's/^/  /' || true
    else
      echo "tools/fuzz.sh: $target FOUND A BUG (exit $rc); end of its log ($log):"
      tail -n 60 "$log"
      echo "tools/fuzz.sh: the input that caused it (reproduce: $build/fuzz/$target FILE):"
      grep -hoE "Test unit written to [^ ]+" "$log" | sed 's/.* to /  /' || echo "  (none written)"
    fi
  } >"$log.verdict"
  echo "$rc" >"$log.rc"
}
# target  max_len  dictionary: the largest seed (dual_arm.urdf, 8.4 kB) fits with room to grow;
# commands mutates scenarios (over the model families), with the scenario's dictionary; page
# mutates a robot folder's URDF (names, mesh filenames) into the page writer, with the URDF's. As
# many targets at once as there are cores, each for SECONDS: the same fuzzing in a fraction of the time.
specs=("urdf 16384 urdf" "scenario 4096 scenario" "study 4096 study" "commands 4096 scenario" "page 8192 urdf")
jobs=$(nproc)
names=()
for spec in "${specs[@]}"; do
  read -r name max_len dict <<<"$spec"
  while (($(jobs -rp | wc -l) >= jobs)); do wait -n || true; done
  echo "tools/fuzz.sh: fuzz_$name for ${seconds} s"
  fuzz_one "$name" "$max_len" "$dict" &
  names+=("$name")
done
wait
for name in "${names[@]}"; do
  cat "$build/fuzz_$name.log.verdict" >&2
  [[ "$(cat "$build/fuzz_$name.log.rc")" == 0 ]] || failed=1
done
exit "$failed"
