#!/usr/bin/env bash
# The main job on the bundled default model: installs what is missing, builds, and runs the
# whole capture operation: the 7-joint arm on its 400 kg satellite grasps a tumbling 50 kg box,
# then holds it with PD servos for 20 s. Prints the summary and the plot's path.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${KDL_SPACE_BUILD_DIR:-$root/build}"
"$root/tools/build.sh"
mkdir -p "$build/demo"
exec "$build/kdl_space" simulate "$root/scenarios/tumbling_box_capture.yaml" --duration 20 \
  --csv "$build/demo/tumbling_box_capture.csv" --plot "$build/demo/tumbling_box_capture.svg"
