#!/usr/bin/env bash
# tools/fuzz.sh [SECONDS]: installs clang and libFuzzer, builds the fuzz targets (KDL_SPACE_FUZZ=ON,
# ASan + UBSan, assertions on) into build-fuzz/ (or $KDL_SPACE_FUZZ_BUILD_DIR) and runs each for
# SECONDS (default 60) on a scratch copy of its seed corpus fuzz/corpus/<target>/ (the repository
# is never written). Fails on any finding (crash, sanitizer report, leak, uncaught exception,
# timeout of one input, memory blow-up) and prints the path of the input that caused it; see
# README "Sanitizers and fuzzing" for turning it into a regression test.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${KDL_SPACE_FUZZ_BUILD_DIR:-$root/build-fuzz}"
seconds="${1:-60}"
[[ "$seconds" =~ ^[0-9]+$ ]] && ((seconds > 0)) || { echo "usage: tools/fuzz.sh [SECONDS]" >&2; exit 2; }

# clang, and libFuzzer with the sanitizer runtimes (Debian 12: libclang-rt-14-dev).
"$root/tools/deps.sh" clang libclang-rt-14-dev
CC=clang CXX=clang++ cmake -S "$root" -B "$build" -DKDL_SPACE_FUZZ=ON \
  -DKDL_SPACE_BUILD_TESTS=OFF -DKDL_SPACE_BUILD_TOOLS=OFF -DKDL_SPACE_BUILD_BENCHMARK=OFF \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" >/dev/null
cmake --build "$build" -j"$(nproc)" --target fuzz_urdf fuzz_scenario fuzz_study fuzz_commands >/dev/null

export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1${UBSAN_OPTIONS:+:$UBSAN_OPTIONS}"
export LSAN_OPTIONS="suppressions=$root/tools/sanitizers/lsan.supp:print_suppressions=0${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
work="$(mktemp -d "${TMPDIR:-/tmp}/kdl_space_fuzz.XXXXXX")"
trap 'rm -rf "$work"' EXIT
artifacts="$build/artifacts"
failed=0
# target  max_len  dictionary: the largest seed (dual_arm.urdf, 8.4 kB) fits with room to grow;
# commands mutates scenarios (over the model families), with the scenario's dictionary.
for spec in "urdf 16384 urdf" "scenario 4096 scenario" "study 4096 study" "commands 4096 scenario"; do
  read -r name max_len dict <<<"$spec"
  target="fuzz_$name"
  mkdir -p "$work/$name" "$artifacts/$name"
  cp "$root/fuzz/corpus/$name/"* "$work/$name/"
  # The inputs that once found a bug are seeds too (tests/data/fuzz_regressions/, if any).
  cp "$root/tests/data/fuzz_regressions/$name/"* "$work/$name/" 2>/dev/null || true
  log="$build/$target.log"
  echo "tools/fuzz.sh: $target for ${seconds} s (log: $log)"
  # -timeout: one input taking longer than 10 s is a hang (a finding); -rss_limit_mb: a blow-up.
  if "$build/fuzz/$target" "$work/$name" -dict="$root/fuzz/$dict.dict" \
      -max_total_time="$seconds" -max_len="$max_len" -timeout=10 -rss_limit_mb=2048 \
      -artifact_prefix="$artifacts/$name/" -print_final_stats=1 >"$log" 2>&1; then
    grep -E "^stat::(number_of_executed_units|new_units_added|peak_rss_mb)|#[0-9]+.*DONE" "$log" | sed 's/^/  /' || true
  else
    rc=$?
    failed=1
    echo "tools/fuzz.sh: $target FOUND A BUG (exit $rc); end of its log:" >&2
    tail -n 60 "$log" >&2
    echo "tools/fuzz.sh: the input that caused it (reproduce: $build/fuzz/$target FILE):" >&2
    grep -hoE "Test unit written to [^ ]+" "$log" | sed 's/.* to /  /' >&2 || echo "  (none written)" >&2
  fi
done
exit "$failed"
