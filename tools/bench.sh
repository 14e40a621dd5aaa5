#!/usr/bin/env bash
# Installs what the benchmark needs (Google Benchmark, and DART for the comparison), builds in
# Release, runs kdl_space_bench side by side on generated chains (N = 7 ... 100) and on the
# default model, and writes docs/benchmarks.md (medians of 5 repetitions, ratios, machine).
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
"$build/kdl_space_bench" "${flags[@]}" --markdown "$chains"
(cd "$root" && "$build/kdl_space_bench" "${flags[@]}" --model urdf/space_arm7.urdf --tip end_effector --markdown "$model")

out="$root/docs/benchmarks.md"
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
  echo "- ours_forward_dynamics: \`ForwardDynamicsSolver::CartToJnt\` (dense, O(n^3));"
  echo "- naive_KDL_G_star: six virtual base joints + \`ChainDynParam::JntToMass\` + \`ChainJntToJacSolver\` + Eigen LLT;"
  echo "- DART_G_star: DART's \`getWorldJacobian\` and \`getInvMassMatrix\` on the same URDF with a free root joint."
  echo
  echo "## Machine"
  echo
  echo '```'
  lscpu | grep -E "Model name|^CPU\(s\)|Thread|MHz" || true
  echo "kernel: $(uname -sr)"
  echo "compiler: $(c++ --version | head -1)"
  echo "load average at the start: $(cut -d' ' -f1-3 /proc/loadavg)"
  echo '```'
  echo
  echo "## Generated chains (N revolute links on a 500 kg base, full inertia tensors)"
  echo
  cat "$chains"
  echo
  echo "## The default model (urdf/space_arm7.urdf, contact end_effector)"
  echo
  cat "$model"
} >"$out"
rm -f "$chains" "$model"
echo "tools/bench.sh: wrote $out"
