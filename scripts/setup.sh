#!/usr/bin/env bash
# Installs the Debian 12 packages lpshoot needs, with apt-get as root (through sudo when not
# root), and only those that are missing. Prints what it installs.
set -euo pipefail

packages=(
  g++ cmake make ccache pkg-config
  libeigen3-dev                      # Eigen 3.4
  liblapack-dev                      # dgbsv, for the banded floor in bench/bench_floor.cpp
  libsundials-dev                    # SUNDIALS 6.4 (KINSOL)
  libnlopt-dev libnlopt-cxx-dev      # NLopt 2.7
  libboost-dev                       # Boost 1.74 (Odeint; SHA-1 for the plugin cache)
  libgtest-dev libbenchmark-dev      # GoogleTest, Google Benchmark
  libcli11-dev nlohmann-json3-dev    # the application
  gnuplot-nox                        # plots
  python3                            # the CLI fuzz test (standard library only)
  python3-dev python3-numpy pybind11-dev   # the Python module
  python3-pytest python3-matplotlib        # its tests and examples
  python3-scipy                      # bench/compare_scipy.py (scipy's solve_bvp, the peer)
  libopenmpi-dev openmpi-bin         # lpshoot study under mpirun
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all required Debian packages are installed"
  exit 0
fi

echo "setup: installing Debian packages with apt-get (as root): ${missing[*]}"
sudo=""
if [ "$(id -u)" != 0 ]; then
  command -v sudo >/dev/null || { echo "setup: not root and no sudo; install as root: apt-get install ${missing[*]}" >&2; exit 1; }
  sudo="sudo"
fi
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
echo "setup: done"
