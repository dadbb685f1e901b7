#!/usr/bin/env bash
# The segmentation table of docs/EVALUATION (docs/journal/pipeline.md) on every simulator
# preset: bottom tier only, flow only, fused (decay = all, the paper's literal
# model), fused (the config's decay), fused + ray cast, side by side on the same
# frames, pixel level and voxel level (bims-eval masks --voxel-size 0.05). Not
# part of CTest (minutes).
#
# Usage, from the repository root after building:
#   scripts/segmentation_table.sh [BUILD_DIR] [DATA_DIR] [RES] [FRAMES] [PRESET...]
# Defaults: build, a temporary folder, 320x240, 150 frames, every preset of
# config/sim/. Each preset is simulated once (seed 1) into DATA_DIR (kept if
# given); the experiment is config/default.ini with the preset's own
# [calibration] (R_IC, time offset) from its ground truth.
set -euo pipefail
BUILD_DIR=${1:-build}
DATA=${2:-}
RES=${3:-320x240}
FRAMES=${4:-150}
shift $(($# < 4 ? $# : 4))
cd "$(dirname "$0")/.."
BIN="$BUILD_DIR/bin"

. scripts/sim_experiment.sh
PRESETS=$(sim_presets "$@")
sim_data_dir

echo "| preset | variant | precision | recall | F1 | IoU | voxel F1 | ATE RMSE [m] | ms/frame (pipeline, median) |"
echo "|---|---|---|---|---|---|---|---|---|"
for p in $PRESETS; do
	rl="$DATA/$p.rawlog"
	gt="$DATA/${p}_gt"
	if [ ! -f "$rl" ]; then
		"$BIN/bims-sim" "config/sim/$p.ini" -o "$rl" -r "$RES" --max-frames "$FRAMES" --seed 1 -q >&2
	fi
	sim_experiment_config "$gt/calibration.ini" "$DATA/$p.ini"
	sim_experiment_config "$gt/calibration.ini" "$DATA/${p}_all.ini" grids.decay=all
	for row in "bottom-only bottom-only $p" "flow-only flow-only $p" \
		"fused,decay=all fused ${p}_all" "fused fused $p" \
		"fused+raycast fused-raycast $p"; do
		read -r name variant cfg <<< "$row"
		out="$DATA/out_${p}_${name//[,=+]/_}"
		"$BIN/bims-run" "$DATA/$cfg.ini" "$rl" -o "$out" --variant "$variant" --overwrite -q > "$out.log" 2>&1 ||
			{ echo "| $p | $name | run failed: see $out.log | | | | | | |"; continue; }
		ev=$("$BIN/bims-eval" masks "$gt/masks" "$out/masks" --depth-valid "$rl" -q --no-plots 2>/dev/null)
		read -r _ _ pr _ re _ f1 _ iou <<< "$(echo "$ev" | tail -n 1)"
		vf1=$(echo "$ev" | sed -n 's/^voxel_total.* F1 \([0-9.na]*\) .*/\1/p')
		ate=$("$BIN/bims-eval" traj "$gt/groundtruth.txt" "$out/trajectory.txt" --no-plot 2>/dev/null |
			awk '/^ate_rmse/ {print $2}')
		ms=$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["stage_ms"]["total"]["median"])' "$out/metrics.json" 2>/dev/null)
		echo "| $p | $name | $pr | $re | $f1 | $iou | ${vf1:--} | $ate | ${ms:--} |"
	done
done
