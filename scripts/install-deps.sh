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
  libzstd-dev liblz4-dev libsqlite3-dev libyaml-cpp-dev
  cyclonedds-dev cyclonedds-tools
  nodejs iproute2
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

# The ROS 2 tests' independent side (tests/ros2_writer: the bags' MCAP and
# CDR writer, the live node's @foxglove/ros2 subscriber; npm packages locked
# in its package-lock.json; never the product's runtime): installed once,
# again when the lock file changes. (iproute2's ip: the node test's private
# network namespace.)
npm_writer() {
  local dir
  dir="$(cd "$(dirname "$0")/.." && pwd)/tests/ros2_writer"
  [ -f "$dir/package-lock.json" ] || return 0
  if ! command -v npm > /dev/null; then
    $SUDO apt-get install -y -qq --no-install-recommends npm || true
  fi
  if [ -f "$dir/node_modules/.package-lock.json" ] &&
    [ "$dir/node_modules/.package-lock.json" -nt "$dir/package-lock.json" ]; then
    return 0
  fi
  echo "[deps] npm ci in tests/ros2_writer (the ROS 2 tests' writer and subscriber)"
  (cd "$dir" && npm ci --no-audit --no-fund --loglevel=error) ||
    echo "[deps] warning: npm ci failed: the ROS 2 bag tests and the node's independent subscriber will skip" >&2
}

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  SUDO="sudo"
fi

if [ ${#missing[@]} -eq 0 ]; then
  echo "[deps] all ${#PACKAGES[@]} packages present"
  npm_writer
  exit 0
fi

echo "[deps] installing ${#missing[@]} missing packages: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
npm_writer
echo "[deps] done"
