#!/usr/bin/env bash
# make demo: the main job on the bundled sample in rawlogs/.
#   1. what the sample holds (bims-info)
#   2. the pipeline, each variant of docs/EVALUATION (bims-run)
#   3. each variant's masks scored against the exact ground truth (bims-eval masks)
# Outputs go to out/demo/<variant>/ (an earlier demo's replaced: --overwrite); the
# table is printed at the end.
set -euo pipefail
BUILD_DIR=${1:-build}
cd "$(dirname "$0")/.."
BIN="$BUILD_DIR/bin"
SAMPLE=rawlogs/pendulum_slow.rawlog
GT=rawlogs/pendulum_slow_gt
CONFIG=config/default.ini
OUT=out/demo

for f in "$SAMPLE" "$GT/masks" "$CONFIG"; do
  [ -e "$f" ] || { echo "demo: $f is missing" >&2; exit 1; }
done

echo "== the bundled sample"
"$BIN/bims-info" "$SAMPLE"

mkdir -p "$OUT"
table="$OUT/summary.txt"
printf '%-14s %9s %9s %9s %9s %9s %9s %12s\n' variant precision recall F1 IoU "voxel F1" frames/s "ATE RMSE m" > "$table"
for v in bottom-only flow-only fused; do
  echo
  echo "== bims-run --variant $v"
  "$BIN/bims-run" "$CONFIG" "$SAMPLE" -o "$OUT/$v" --variant "$v" --overwrite -q | tee "$OUT/$v.log"
  ev=$("$BIN/bims-eval" masks "$GT/masks" "$OUT/$v/masks" --depth-valid "$SAMPLE" --overwrite -q)
  total=$(echo "$ev" | tail -n 1)
  vf1=$(echo "$ev" | sed -n 's/^voxel_total.* F1 \([0-9.na]*\) .*/\1/p')
  ate=$("$BIN/bims-eval" traj "$GT/groundtruth.txt" "$OUT/$v/trajectory.txt" -o "$OUT/$v/trajectory.png" 2>/dev/null |
        awk '/^ate_rmse/ {print $2}')
  fps=$(sed -n 's/^ *"fps": *\([0-9.]*\).*/\1/p' "$OUT/$v/metrics.json" | head -n 1)
  # total precision P recall R F1 F IoU I
  read -r _ _ p _ r _ f _ i <<< "$total"
  printf '%-14s %9s %9s %9s %9s %9s %9s %12s\n' "$v" "$p" "$r" "$f" "$i" "$vf1" "$fps" "$ate" >> "$table"
done

echo
echo "== segmentation of $SAMPLE against its ground truth (all frames, valid-depth pixels)"
cat "$table"
echo
echo "outputs: $OUT/<variant>/ (trajectory.txt, masks/, metrics.json, static_map.ply, segmented.rawlog);"
echo "         mask overlays in $OUT/<variant>/masks_eval/; this table in $table"
