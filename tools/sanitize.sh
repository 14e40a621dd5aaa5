#!/usr/bin/env bash
# Installs what is missing, builds the library, the tool and the tests (not the benchmark) with
# AddressSanitizer and UndefinedBehaviorSanitizer (KDL_SPACE_SANITIZE=ON, assertions on) into
# build-asan/ (or $KDL_SPACE_ASAN_BUILD_DIR), and runs the whole test suite there. Any sanitizer
# report fails the test that triggered it. Third-party libraries (KDL, urdfdom, yaml-cpp) are not
# instrumented.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${KDL_SPACE_ASAN_BUILD_DIR:-$root/build-asan}"
"$root/tools/deps.sh"
# -O1 (half the compile time of -O2 under the sanitizers, the same floating-point code: no
# fast-math, no FMA on x86-64's baseline, so the same tolerances hold) with line tables (-g1: a
# report names file and line), without NDEBUG: Eigen's and our assertions stay armed. Only what
# the suite runs is built: the Python module is off with the sanitizers, the benchmark is off here
# (its smoke tests run in tools/test.sh), the tool's suite is a representative set
# (tests/CMakeLists.txt; the normal build runs it whole).
source "$root/tools/cmake_generator.sh" "$build"
cmake -S "$root" -B "$build" "${generator_args[@]}" -DKDL_SPACE_SANITIZE=ON -DKDL_SPACE_BUILD_BENCHMARK=OFF \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" "$@" >/dev/null
cmake --build "$build" -j"$(nproc)" >"$build/build.log" 2>&1 ||
  { grep -E -A12 "^FAILED|error" "$build/build.log" | head -n 80 >&2; echo "tools/sanitize.sh: the build failed (log: $build/build.log)" >&2; exit 1; }
# Every report is fatal (UBSan too: -fno-sanitize-recover at compile time, halt_on_error here);
# leaks are reported at exit. Suppressions, each with its reason: tools/sanitizers/.
export ASAN_OPTIONS="detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1:check_initialization_order=1:abort_on_error=0${ASAN_OPTIONS:+:$ASAN_OPTIONS}"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1${UBSAN_OPTIONS:+:$UBSAN_OPTIONS}"
export LSAN_OPTIONS="suppressions=$root/tools/sanitizers/lsan.supp:print_suppressions=0${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
ctest --test-dir "$build" --output-on-failure -j"$(nproc)"
