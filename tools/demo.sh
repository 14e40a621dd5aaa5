#!/usr/bin/env bash
# The main job on the bundled default model: installs what is missing, builds, and prints the
# summary of a capture: the 7-joint arm on its 400 kg satellite grasps a tumbling 50 kg box.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/tools/build.sh"
exec "${KDL_SPACE_BUILD_DIR:-$root/build}/kdl_space" capture "$root/scenarios/tumbling_box_capture.yaml"
