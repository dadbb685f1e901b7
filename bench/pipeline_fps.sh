#!/usr/bin/env bash
# End-to-end speed of bims-run at 640x480 and 320x240 on simulator data
# (not part of CTest). Usage: bench/pipeline_fps.sh [BUILD_DIR] [FRAMES]
# Prints, per resolution and variant, frames/s and per-stage median/p95 ms
# from bims-run's metrics.json.
set -euo pipefail
BUILD_DIR=${1:-build}
FRAMES=${2:-120}
cd "$(dirname "$0")/.."
BIN="$BUILD_DIR/bin"
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT

for res in 640x480 320x240; do
  "$BIN/bims-sim" config/sim/pendulum_slow.ini -o "$TMP/$res.rawlog" --frames "$FRAMES" --resolution "$res" --seed 1 -q
  for v in fused fused-raycast; do
    "$BIN/bims-run" config/default.ini "$TMP/$res.rawlog" -o "$TMP/out_${res}_$v" --variant "$v" -q > "$TMP/log" 2>&1
    echo "== $res $v ($FRAMES frames)"
    grep -E "frames/s|median|input|egomotion|flow|grids|total" "$TMP/log" | grep -v "^outputs"
  done
done
