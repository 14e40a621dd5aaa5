# Sourced by tools/build.sh, sanitize.sh and fuzz.sh: the arguments every configure of kdl_space
# takes, in the array `generator_args`, for the build folder $1. Ninja (Debian's ninja-build: it
# schedules every target's objects on the cores at once and logs each one's time, which
# tools/ci_times.sh reads) for a new build folder; a folder configured before keeps its generator
# (CMake refuses to change it). ccache when installed (Debian's ccache: a warm machine rebuilds in
# seconds; a cold one pays a few per cent).
generator_args=()
if [[ ! -f "$1/CMakeCache.txt" ]] && command -v ninja >/dev/null; then
  generator_args+=(-G Ninja)
fi
if command -v ccache >/dev/null; then
  generator_args+=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
