#!/usr/bin/env bash
# make demo: the main job on the bundled sample in rawlogs/.
set -euo pipefail
BUILD_DIR=${1:-build}
cd "$(dirname "$0")/.."
SAMPLE=rawlogs/pendulum_slow.rawlog
if [ ! -f "$SAMPLE" ]; then
  echo "demo: $SAMPLE is missing" >&2
  exit 1
fi
"$BUILD_DIR/bin/bims-info" "$SAMPLE"
