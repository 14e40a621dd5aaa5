#!/usr/bin/env bash
# Installs the Debian 12 packages kdl_space needs to build, test and run, when missing, plus any
# packages given as arguments. Used by tools/demo.sh, tools/test.sh and tools/bench.sh; safe to
# run again (installs nothing if all are present).
set -euo pipefail

packages=(
  build-essential cmake pkg-config ninja-build ccache                         # ccache: a warm machine's rebuilds
  liborocos-kdl-dev libkdl-parser-dev liburdfdom-dev libconsole-bridge-dev libtinyxml-dev libexpat1-dev
  libeigen3-dev libgtest-dev libbenchmark-dev nlohmann-json3-dev libcli11-dev libyaml-cpp-dev
  libnlopt-cxx-dev                                                           # capture planning (kdl_space plan)
  libsdformat-dev                                                            # Gazebo SDF model files (the library reads them)
  libmujoco-dev                                                              # MuJoCo: an independent engine in the tests (MJCF export)
  gnuplot-nox
  libjs-three                                                                # three.js, inlined into simulate --html's page
  chromium                                                                   # headless browser: the --html page's tests
  pybind11-dev python3-pybind11 python3-dev python3-numpy python3-pytest   # the Python module (python/)
  python3-pytest-xdist                                                       # its tests on every core (pytest -n)
  python3-pykdl                                                              # its PyKDL interop tests
  python3-matplotlib                                                         # examples/notebook.py
  python3-distributed python3-dask                                           # studies on Dask (kdl_space.study)
  "$@"
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "tools/deps.sh: installing ${missing[*]}" >&2
  sudo_cmd=()
  [ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
  export DEBIAN_FRONTEND=noninteractive
  "${sudo_cmd[@]}" apt-get update -qq
  "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
