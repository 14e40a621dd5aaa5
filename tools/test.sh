#!/usr/bin/env bash
# Installs what is missing, builds, and runs every test (unit, reference, command line, and the
# downstream package test).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${KDL_SPACE_BUILD_DIR:-$root/build}"
"$root/tools/build.sh"
ctest --test-dir "$build" --output-on-failure -j"$(nproc)"
