#!/usr/bin/env bash
# Installs what is missing, builds the library, the tool, the tests (not the benchmark) and the fuzz
# targets with AddressSanitizer and UndefinedBehaviorSanitizer (clang, assertions on) into
# build-asan/ (or $KDL_SPACE_ASAN_BUILD_DIR; tools/sanitized_build.sh), and runs the library's
# suites and a representative set of the tool's there. Any sanitizer report fails the test that
# triggered it. Third-party libraries (KDL, urdfdom, yaml-cpp) are not instrumented.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
source "$root/tools/sanitized_build.sh"  # build-asan/: clang, ASan + UBSan, the fuzz targets too
sanitized_build
# Every report is fatal (UBSan too: -fno-sanitize-recover at compile time, halt_on_error here);
# leaks are reported at exit. Suppressions, each with its reason: tools/sanitizers/.
export ASAN_OPTIONS="detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1:check_initialization_order=1:abort_on_error=0${ASAN_OPTIONS:+:$ASAN_OPTIONS}"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1${UBSAN_OPTIONS:+:$UBSAN_OPTIONS}"
export LSAN_OPTIONS="suppressions=$root/tools/sanitizers/lsan.supp:print_suppressions=0${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
# The numerical sweeps of tools/sanitizers/heavy_tests.txt are left out (tools/test.sh runs them):
# each name must still be a test, so a renamed one is not silently run again.
heavy=$(sed -e 's/#.*//' -e 's/[[:space:]]*$//' -e '/^$/d' "$root/tools/sanitizers/heavy_tests.txt")
listed=$(ctest --test-dir "$build" -N | sed -n 's/^ *Test *#[0-9]*: //p')
for name in $heavy; do
  grep -qxF "$name" <<<"$listed" ||
    { echo "tools/sanitize.sh: tools/sanitizers/heavy_tests.txt names $name, which is no test: rename or remove it" >&2; exit 1; }
done
ctest --test-dir "$build" --output-on-failure -j"$(nproc)" -E "^($(paste -sd'|' <<<"$heavy"))\$"
