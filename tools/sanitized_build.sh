# Sourced by tools/sanitize.sh and tools/fuzz.sh: `sanitized_build TARGET...` configures the one
# instrumented build, build-asan/ (or $KDL_SPACE_ASAN_BUILD_DIR, in `$build`), and builds the given
# targets (none: all). One build serves both: clang with AddressSanitizer + UBSan and libFuzzer's
# coverage (KDL_SPACE_SANITIZE=ON, KDL_SPACE_FUZZ=ON), so the library the suites run under the
# sanitizers is the library the fuzz targets drive, compiled once (CI compiled it twice, with two
# compilers, before). clang: its ASan build compiled in 30 % less time than GCC's (measured on the
# suites). -O1 (half the compile time of -O2 under the sanitizers, the same floating-point code: no
# fast-math, no FMA on x86-64's baseline, so the same tolerances hold) with line tables (a report
# names file and line), without NDEBUG: Eigen's and our assertions stay armed. A unity build, as
# tools/build.sh's (the suites stay one object per file): the library's, reports' and commands' objects
# add to ~2,950 s of compiling one file at a time under ASan (an earlier build's log), 1,185 s in
# batches (measured cold, 2 cores). Only what the suites
# run is built: no Python module, no benchmark (its smoke tests run in tools/test.sh), the tool's
# suite by a representative set (tests/CMakeLists.txt; the normal build runs it whole).
build="${KDL_SPACE_ASAN_BUILD_DIR:-$root/build-asan}"
sanitized_build() {
  "$root/tools/deps.sh" clang libclang-rt-14-dev  # clang, and libFuzzer with the sanitizer runtimes
  source "$root/tools/cmake_generator.sh" "$build"
  CC=clang CXX=clang++ cmake -S "$root" -B "$build" "${generator_args[@]}" -DKDL_SPACE_SANITIZE=ON \
    -DKDL_SPACE_FUZZ=ON -DKDL_SPACE_BUILD_BENCHMARK=OFF -DKDL_SPACE_BUILD_PYTHON=OFF \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" \
    -DCMAKE_UNITY_BUILD=ON >/dev/null
  # The suites that test private functions link the library's objects twice, in libkdl_space.so and
  # in the static kdl_space_internal (tests/CMakeLists.txt): the same globals, the same sizes. clang's
  # ASan reports that as an ODR violation at the default level 2; level 1 still reports two
  # definitions of a name with different sizes, the ODR violations that matter. Set here because
  # the build runs each suite (GoogleTest's discovery), and in tools/sanitize.sh.
  export ASAN_OPTIONS="detect_odr_violation=1${ASAN_OPTIONS:+:$ASAN_OPTIONS}"
  local targets=()
  for t in "$@"; do targets+=(--target "$t"); done
  cmake --build "$build" -j"$(nproc)" ${targets[@]+"${targets[@]}"} >"$build/build.log" 2>&1 ||
    { grep -E -A12 "^FAILED|error" "$build/build.log" | head -n 80 >&2
      echo "$(basename "$0"): the build failed (log: $build/build.log)" >&2; return 1; }
}
