#!/usr/bin/env bash
# The main job on the bundled default model: installs what is missing, builds only what the demo
# runs (the library and the tool kdl_space: no test, benchmark or Python module; tools/test.sh
# builds the rest in the same build/), and runs the whole capture operation: the 7-joint arm on
# its 400 kg satellite grasps a tumbling 50 kg box, then holds it with PD servos for 20 s. Prints
# the summary, then where the tool, the library and this run's CSV and plot are.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${KDL_SPACE_BUILD_DIR:-$root/build}"
"$root/tools/build.sh" --target kdl_space_cli
mkdir -p "$build/demo"
"$build/kdl_space" simulate "$root/scenarios/tumbling_box_capture.yaml" --duration 20 \
  --csv "$build/demo/tumbling_box_capture.csv" --plot "$build/demo/tumbling_box_capture.svg"
library="$(find "$build" -maxdepth 1 -name 'libkdl_space.so.*.*' -print -quit)"
cat <<MSG

tools/demo.sh: built into $build/
  the tool:    $build/kdl_space       (kdl_space --help)
  the library: ${library:-$build/libkdl_space.so}
  this run:    $build/demo/tumbling_box_capture.csv, $build/demo/tumbling_box_capture.svg
  the package from the build tree: find_package(kdl_space) with -Dkdl_space_DIR=$build
MSG
