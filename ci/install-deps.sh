#!/usr/bin/env bash
# Installs the Debian 12 packages PE-SLAM Bench builds and runs with.
# Run as root on a fresh Debian 12 machine.  Idempotent.
set -euo pipefail
PKGS=(
  build-essential cmake ninja-build pkg-config ccache git
  lld   # the linker (about five times faster than GNU ld on the test programs)
  libeigen3-dev libopencv-dev libceres-dev libyaml-cpp-dev libcli11-dev
  libmujoco-dev libqhull-dev
  libegl-dev libegl-mesa0 libgl-dev libgles-dev libosmesa6-dev libgl1-mesa-dri
  libopenni2-dev
  libnanoflann-dev   # k-d trees for map accuracy
  libzstd-dev        # compressed spill files of the dense map
  nlohmann-json3-dev # the tests parse every JSON file pvbench writes with a strict parser
  python3 python3-yaml   # the tests read the motion files back with Python's csv and yaml modules
  libfreenect-dev libfreenect0.5 libfreenect-bin   # Kinect v1 plug-in and fakenect playback
  libgtest-dev libgmock-dev libbenchmark-dev
  clang libclang-rt-14-dev   # the libFuzzer targets (ci/fuzz.sh)
)
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PKGS[@]} packages present"
  exit 0
fi
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update
$SUDO apt-get install -y --no-install-recommends "${missing[@]}"
