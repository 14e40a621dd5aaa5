#!/usr/bin/env bash
# How fast the page of `--html` opens: a 20 s run of the 44-joint humanoid
# (tests/data/real_patterns/humanoid44.urdf, a plain tumbling motion, a row every 0.01 s) written
# by `kdl_space simulate --html`, then opened RUNS times in headless Chromium; prints the page's
# size and, per run, the time from the navigation's start to window.kdlSpace.ready
# (performance.now() at ready, from the page's #selftest output) and the whole browser's wall
# time. A measurement, not a test: speed is not asserted in the test suite.
#   tools/bench_html.sh [KDL_SPACE_CLI] [RUNS]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cli="${1:-$root/build/kdl_space}"
runs="${2:-5}"
chromium="$(command -v chromium || command -v chromium-browser)" ||
  { echo "tools/bench_html.sh: no chromium (Debian package chromium)" >&2; exit 3; }
dir="$(mktemp -d)"
trap 'rm -rf "$dir"' EXIT
cat >"$dir/humanoid.yaml" <<YAML
robot:
  urdf: $root/tests/data/real_patterns/humanoid44.urdf
  base: {twist: [0.02, 0.01, 0, 0.05, -0.03, 0.04]}
simulation:
  duration: 20
  output_step: 0.01
  integrator: rosenbrock
  rtol: 1.0e-6
  atol: 1.0e-8
YAML
start=$(date +%s.%N)
"$cli" simulate "$dir/humanoid.yaml" --html "$dir/humanoid.html" >/dev/null 2>"$dir/stderr"
end=$(date +%s.%N)
echo "page: $(stat -c %s "$dir/humanoid.html") bytes; simulate --html took $(echo "$end - $start" | bc) s"
echo "machine: $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg), $("$chromium" --version 2>/dev/null)"
for k in $(seq "$runs"); do
  start=$(date +%s.%N)
  out=$("$chromium" --headless --no-sandbox --disable-gpu --enable-unsafe-swiftshader --dump-dom \
        "file://$dir/humanoid.html#selftest=0" 2>/dev/null | sed 's/&quot;/"/g')
  end=$(date +%s.%N)
  ready=$(printf '%s' "$out" | sed -n 's/.*"readyMs":\([0-9.]*\).*/\1/p')
  errors=$(printf '%s' "$out" | sed -n 's/.*"errors":\(\[[^]]*\]\).*/\1/p')
  echo "run $k: ready after ${ready:-?} ms (errors ${errors:-?}); chromium's wall time $(echo "$end - $start" | bc) s"
done
