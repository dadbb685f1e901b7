#!/usr/bin/env bash
# Installs every Debian package bims needs (build, tests, GUI tests, benchmarks).
# Idempotent: a fast no-op when everything is already present.
#   scripts/install-deps.sh        what make demo / make test need
#   scripts/install-deps.sh fuzz   and clang with libFuzzer (scripts/fuzz.sh)
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build lld pkg-config clang-format ccache help2man
  libmrpt-dev mrpt-apps
  libopencv-dev libeigen3-dev nlohmann-json3-dev libdeflate-dev
  libopenni2-dev openni2-utils
  libwxgtk3.2-dev
  liboctomap-dev
  librosbag-storage-dev libcv-bridge-dev libsensor-msgs-dev pluginlib-dev
  libroslz4-dev libbz2-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  xvfb xauth imagemagick xdotool x11-apps libgl1-mesa-dri
  python3-dev pybind11-dev python3-numpy python3-opencv
  slurm-wlm munge parallel
)
if [ "${1:-}" = fuzz ]; then
  PACKAGES+=(clang libclang-rt-14-dev)
fi

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "[deps] all ${#PACKAGES[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  SUDO="sudo"
fi
echo "[deps] installing ${#missing[@]} missing packages: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
echo "[deps] done"
