#!/usr/bin/env bash
# Installs what the benchmark needs (Google Benchmark, and DART for the comparison), builds in
# Release, runs kdl_space_bench side by side on generated chains (N = 7 ... 100; the 10 s
# simulations at 7 and 100) and on the default model, and writes docs/benchmarks.md (medians of
# 5 repetitions, ratios, machine and its load).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${KDL_SPACE_BENCH_BUILD_DIR:-$root/build-release}"
# DART only for the comparison: the benchmark runs without it if it cannot be installed.
"$root/tools/deps.sh" libdart-dev libdart-utils-urdf-dev ||
  { echo "tools/bench.sh: DART could not be installed; benchmarking without it" >&2; "$root/tools/deps.sh"; }
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DKDL_SPACE_BUILD_TESTS=OFF -DKDL_SPACE_BUILD_TOOLS=OFF >/dev/null
cmake --build "$build" -j"$(nproc)" --target kdl_space_bench >/dev/null

flags=(--benchmark_repetitions=5 --benchmark_min_time=0.2 --benchmark_report_aggregates_only=true)
chains=$(mktemp) model=$(mktemp)
load_start=$(cut -d' ' -f1-3 /proc/loadavg)
"$build/kdl_space_bench" "${flags[@]}" --markdown "$chains"
(cd "$root" && "$build/kdl_space_bench" "${flags[@]}" --model urdf/space_arm7.urdf --tip end_effector --markdown "$model")
load_end=$(cut -d' ' -f1-3 /proc/loadavg)

out="$root/docs/benchmarks.md"
# The sections measured by hand (below the marker) are kept as they are.
marker="<!-- measured by hand: every section below this line is kept by tools/bench.sh -->"
by_hand=$(awk -v m="$marker" '$0 == m { kept = 1 } kept' "$out" 2>/dev/null || true)
{
  echo "# Benchmarks"
  echo
  echo "Written by \`tools/bench.sh\` on $(date -u +%Y-%m-%d): \`kdl_space_bench\`, Release build,"
  echo "medians of 5 repetitions of the CPU time per call, every method timed side by side in one run on"
  echo "the same URDF."
  echo "A call includes everything from joint positions to the result (forward kinematics included);"
  echo "every method alternates between two configurations so that no library reuses a cached result."
  echo
  echo "- ours_G_star: \`RecursiveExIITSolver\` compute + G_star (O(n) articulated-body recursion);"
  echo "- ours_J_star, ours_H_star: \`FreeFloatingSolver\` compute (composite-rigid-body pass, Cholesky of H* and H) + query;"
  echo "- ours_capture_state: G*, the capture impulse of a 50 kg box and the velocity jumps of base and joints;"
  echo "- ours_capture_solve: the capture impulse alone for a given G* and target (eq. 24);"
  echo "- ours_capture_end_to_end: the library's capture path from a state: \`FloatingSide\` (kinematics, momentum,"
  echo "  energy, G* by the O(n) recursion) + \`RigidBodySide\` + \`collide\` (impulse, whole state after of both);"
  echo "- ours_forward_dynamics: \`ForwardDynamicsSolver::CartToJnt\` from the state (forward kinematics, then"
  echo "  Featherstone's articulated-body algorithm with a floating base, O(n));"
  echo "- crb_forward_dynamics: the library's previous route, kept as the tests' second route and compiled into the"
  echo "  benchmark (\`tests/support/crb_forward_dynamics\`: \`FreeFloatingSolver\` compute, a Newton-Euler bias,"
  echo "  Cholesky of the (6+n)^2 mass matrix);"
  echo "- naive_KDL_G_star: six virtual base joints + \`ChainDynParam::JntToMass\` + \`ChainJntToJacSolver\` + Eigen LLT;"
  echo "- DART_G_star: DART's \`getWorldJacobian\` and \`getInvMassMatrix\` on the same URDF with a free root joint;"
  echo "- DART_forward_dynamics: DART's \`setPositions\`, \`setVelocities\`, \`setForces\` and \`computeForwardDynamics\`"
  echo "  on the same URDF with a free root joint;"
  echo "- ours_simulate_10s, crb_simulate_10s: 10 s of free motion (dopri5, rtol 1e-10) by \`Simulator::run\`, and by"
  echo "  the same loop on the previous route (\`tests/support\`: per derivative the dense compute and base twist, then"
  echo "  the dense forward dynamics, as the library ran it before); one call = the whole run."
  echo
  echo "Before timing, the benchmark checks that the forward dynamics of the three routes agree to 1e-9 (per block:"
  echo "base linear, base angular and joint accelerations, ||a - b|| / ||b||) at both configurations of every case,"
  echo "and that the two simulations take the same steps and end within 1e-9 after 1 s and 1e-6 after 10 s (the"
  echo "round-off of the derivatives, amplified by a folded 100-link chain's motion); it aborts if not."
  echo
  echo "## Machine"
  echo
  echo '```'
  lscpu | grep -E "Model name|^CPU\(s\)|Thread|MHz" || true
  echo "kernel: $(uname -sr)"
  echo "compiler: $(c++ --version | head -1)"
  echo "load average at the start: $load_start; at the end: $load_end (1, 5, 15 min; the machine is shared)"
  echo '```'
  echo
  echo "## Generated chains (N revolute links on a 500 kg base, full inertia tensors)"
  echo
  cat "$chains"
  echo
  echo "## The default model (urdf/space_arm7.urdf, contact end_effector)"
  echo
  cat "$model"
  if [ -n "$by_hand" ]; then
    echo
    echo "$by_hand"
  fi
} >"$out.new"
mv "$out.new" "$out"
rm -f "$chains" "$model"
echo "tools/bench.sh: wrote $out"
