#!/usr/bin/env bash
# tools/build.sh [--target TARGET]... [CMAKE_ARGS...]: installs what is missing, configures kdl_space
# into build/ (or $KDL_SPACE_BUILD_DIR) and builds it: everything (library, tool, tests, benchmark,
# Python module), or only the given targets and what they need (tools/demo.sh: --target
# kdl_space_cli). The other arguments go to cmake's configure step. Configuring is always the same,
# so a later build of everything (tools/test.sh) reuses what a build of some targets compiled.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${KDL_SPACE_BUILD_DIR:-$root/build}"
targets=()
while (($#)); do
  case "$1" in
    --target) (($# >= 2)) || { echo "tools/build.sh: --target needs a name" >&2; exit 2; }
              targets+=(--target "$2"); shift 2 ;;
    --target=*) targets+=(--target "${1#--target=}"); shift ;;
    *) break ;;
  esac
done
"$root/tools/deps.sh"
source "$root/tools/cmake_generator.sh" "$build"
# RelWithDebInfo with line tables only (-g1: a backtrace names file and line; full -g took 65 % more
# compile time, measured on the test files): the same -O2 code. For a debugger's view of the
# locals, pass -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g -DNDEBUG" (the arguments come after these).
# A unity build (CMake's: up to 8 files of a target compiled as one): the headers and the templates
# every file instantiates again (Eigen's, GoogleTest's) compiled once a batch. For the quickest
# rebuild of one edited file, pass -DCMAKE_UNITY_BUILD=OFF.
cmake -S "$root" -B "$build" "${generator_args[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" -DCMAKE_UNITY_BUILD=ON "$@" >/dev/null
# Quiet when it builds; on a failure, what failed and why (the build's own log, build.log).
cmake --build "$build" -j"$(nproc)" ${targets[@]+"${targets[@]}"} >"$build/build.log" 2>&1 ||
  { grep -E -A12 "^FAILED|error" "$build/build.log" | head -n 80 >&2; echo "tools/build.sh: the build failed (log: $build/build.log)" >&2; exit 1; }
