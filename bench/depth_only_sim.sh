#!/usr/bin/env bash
# Every simulator preset as a depth-only sensor ([rgb] enabled = false: no
# intensity image, as a phone's LiDAR without its video or a time-of-flight
# camera), segmented by bims-run with config/default.ini (the preset's own
# [calibration]) with [pipeline] surface_fill = off and = depth-only (the
# default) side by side: pixel precision, recall, F1 against the simulator's
# masks, and ATE. Not part of CTest (~2 minutes at 320x240, 150 frames).
#
#   bench/depth_only_sim.sh [BUILD_DIR] [DATA_DIR] [RES] [FRAMES] [PRESET...]
#
# Defaults: build, a temporary folder, 320x240, 150 frames, every preset of
# config/sim/ (seed 1).
set -euo pipefail
BUILD_DIR=${1:-build}
DATA=${2:-}
RES=${3:-320x240}
FRAMES=${4:-150}
shift $(($# < 4 ? $# : 4))
cd "$(dirname "$0")/.."
BIN="$BUILD_DIR/bin"
for b in bims-sim bims-run bims-eval; do
	[ -x "$BIN/$b" ] || { echo "depth_only_sim.sh: $BIN/$b missing (build first)" >&2; exit 1; }
done
. scripts/sim_experiment.sh
PRESETS=$(sim_presets "$@")
sim_data_dir

echo "| preset | surface_fill | precision | recall | F1 | ATE RMSE [m] |"
echo "|---|---|---|---|---|---|"
for p in $PRESETS; do
	scene="$DATA/${p}_depth_only.ini"
	rl="$DATA/$p.rawlog"
	gt="$DATA/${p}_gt"
	{ cat "config/sim/$p.ini"; printf '\n[rgb]\nenabled=false\n'; } > "$scene"
	[ -f "$rl" ] || "$BIN/bims-sim" "$scene" -o "$rl" -r "$RES" --max-frames "$FRAMES" --seed 1 -q >&2
	for fill in off depth-only; do
		cfg="$DATA/${p}_$fill.ini"
		sim_experiment_config "$gt/calibration.ini" "$cfg" pipeline.surface_fill=$fill
		out="$DATA/out_${p}_$fill"
		"$BIN/bims-run" "$cfg" "$rl" -o "$out" --overwrite -q > "$out.log" 2>&1 ||
			{ echo "| $p | $fill | run failed: see $out.log | | | |"; continue; }
		read -r _ _ pr _ re _ f1 _ <<< "$("$BIN/bims-eval" masks "$gt/masks" "$out/masks" --depth-valid "$rl" -q --no-plots 2>/dev/null | tail -n 1)"
		ate=$("$BIN/bims-eval" traj "$gt/groundtruth.txt" "$out/trajectory.txt" --no-plot 2>/dev/null |
			awk '/^ate_rmse/ {print $2}')
		echo "| $p | $fill | $pr | $re | $f1 | $ate |"
	done
done
