#!/usr/bin/env bash
# The main job on the bundled default model: installs what is missing, builds, and prints the
# free-floating report (mass, CoM, I_g, H*, J*, G*) of the 7-joint arm on its satellite.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/tools/build.sh"
exec "${KDL_SPACE_BUILD_DIR:-$root/build}/kdl_space" inspect --urdf "$root/urdf/space_arm7.urdf" \
  --tip end_effector --q joint2=0.6 joint4=-1.1 joint6=0.8 --base-rpy 0 0 0.3
