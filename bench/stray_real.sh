#!/usr/bin/env bash
# A phone's LiDAR and IMU against ARKit (issue 34's figures; not part of CTest,
# ~1 minute): imports a Stray Scanner capture with CONFIG, then prints
#   1. the IMU attitude filter against ARKit's attitude: tilt RMS [deg] and
#      heading drift [deg/min] (bims-odom --attitude, bims-eval attitude; the
#      odometry's attitude levelled by the inertial filter's gravity too,
#      --gravity-attitude, when CONFIG has [inertial] enable = true; the
#      filter's first init_time_s seconds left out), the IMU alone;
#   2. bims-calib-imu: R_IC from the capture alone, its angle to CONFIG's and
#      its 1-sigma uncertainty;
#   3. the egomotion against ARKit's poses (a reference, not ground truth):
#      ATE RMSE (SE(3)-aligned), RPE over 1 s, frames measured, for depth +
#      IMU (bims-odom mode imu), depth only without the IMU (mode vision), and
#      bims-run (its moving masks fed back) for the variants; and the largest
#      per-frame translation error [m] with the frames over 3 cm (bims-eval
#      traj's max_frame_trans_err, frames_over_jump: poses paired with the
#      reference's by time stamp);
#   4. bims-run's masks against the capture's masks_proxy labels (255 moving,
#      0 static, 150 and 50 not scored; paired by time stamp): precision,
#      recall, F1, IoU, the share of labelled-static pixels called moving
#      (all frames, and the frames without a moving label), frames/s end to
#      end (256x192).
#
#   bench/stray_real.sh [BUILD_DIR] [DATA_DIR] [CONFIG] [VARIANT...]
#
# Defaults: build, a temporary folder, config/stray.ini, fused and
# bottom-only. The capture: ../shared/data/stray_early (BIMS_STRAY=DIR for
# another Stray Scanner capture; the segmentation needs its masks_proxy/).
set -euo pipefail
BUILD_DIR=${1:-build}
DATA=${2:-}
CONFIG=${3:-config/stray.ini}
shift $(($# < 3 ? $# : 3))
VARIANTS=${*:-fused bottom-only}
cd "$(dirname "$0")/.."
BIN="$BUILD_DIR/bin"
STRAY=${BIMS_STRAY:-../shared/data/stray_early}
for b in bims-run bims-odom bims-eval bims-calib-imu bims-import-stray; do
	[ -x "$BIN/$b" ] || { echo "stray_real.sh: $BIN/$b missing (build first)" >&2; exit 1; }
done
[ -d "$STRAY/depth" ] || { echo "stray_real.sh: $STRAY is not a Stray Scanner capture" >&2; exit 1; }
if [ -z "$DATA" ]; then
	DATA=$(mktemp -d)
	trap 'rm -rf "$DATA"' EXIT
fi
mkdir -p "$DATA"
RAWLOG="$DATA/stray.rawlog"
REF="$DATA/stray_arkit_reference.txt"
"$BIN/bims-import-stray" "$STRAY" -o "$RAWLOG" -c "$CONFIG" -q > "$DATA/import.log" 2>&1 ||
	{ cat "$DATA/import.log" >&2; exit 1; }
sed 's/^/    /' "$DATA/import.log"
INIT=$("$BIN/bims-run" --print-config "$CONFIG" | awk -F'[ =]+' '/^init_time_s/{print $2}')

echo
echo "1. IMU attitude filter vs ARKit (first ${INIT} s left out)"
INERTIAL=$("$BIN/bims-run" --print-config "$CONFIG" | awk -F'[ =]+' '/^\[/{s=$0} s=="[inertial]" && /^enable/{print $2}')
GRAV=()
[ "$INERTIAL" = true ] && GRAV=(--gravity-attitude "$DATA/attitude_gravity.txt")
"$BIN/bims-odom" "$CONFIG" "$RAWLOG" -o "$DATA/odom_imu.txt" --attitude "$DATA/attitude.txt" "${GRAV[@]}" \
	--csv "$DATA/odom_imu.csv" -q 2> "$DATA/odom_imu.log"
"$BIN/bims-eval" attitude "$REF" "$DATA/attitude.txt" --ref-up y --skip-s "$INIT" | sed 's/^/    /'
if [ ${#GRAV[@]} -gt 0 ]; then
	echo "    the odometry's attitude levelled by the inertial filter's gravity (bims-odom --gravity-attitude):"
	"$BIN/bims-eval" attitude "$REF" "$DATA/attitude_gravity.txt" --ref-up y --skip-s "$INIT" | sed 's/^/    /'
fi

echo
echo "2. bims-calib-imu (R_IC from the capture alone)"
"$BIN/bims-calib-imu" "$CONFIG" "$RAWLOG" -q > "$DATA/calib.log" 2>&1 || true
grep -E "frame pairs|uncertainty|angle to|error|warning" "$DATA/calib.log" | sed 's/^/    /'

measured() { # bims-odom CSV: frames whose motion was measured (anchored)
	awk -F, 'NR > 2 && $2 ~ /anchored/ {a++} NR > 2 {n++} END{printf "%d of %d", a, n}' "$1"
}
traj() { # EST -> "ate | rpe_t | rpe_r"
	"$BIN/bims-eval" traj "$REF" "$1" --no-plot 2>/dev/null |
		awk '/^ate_rmse/{a=$2} /^rpe_trans_rmse/{t=$2} /^rpe_rot_rmse/{r=$2} END{printf "%s | %s | %s", a, t, r}'
}
jumps() { # EST -> "max per-frame translation error | frames over 3 cm"
	"$BIN/bims-eval" traj "$REF" "$1" --no-plot --jump-m 0.03 2>/dev/null |
		awk '/^max_frame_trans_err/{m=$2} /^frames_over_jump/{n=$2 " of " $4} END{printf "%s | %s", m, n}'
}
echo
echo "3. Egomotion vs ARKit's poses"
echo
echo "| run | ATE RMSE [m] | RPE [m/s] | RPE [deg/s] | frames measured | egomotion ms (median) | max per-frame translation error [m] | frames over 3 cm |"
echo "|---|---|---|---|---|---|---|---|"
"$BIN/bims-odom" "$CONFIG" "$RAWLOG" -o "$DATA/odom_vision.txt" --mode vision \
	--csv "$DATA/odom_vision.csv" -q 2> "$DATA/odom_vision.log"
for m in imu vision; do
	ms=$(sed -n 's/.*egomotion \([0-9.]*\).*/\1/p' "$DATA/odom_$m.log")
	what=$([ $m = imu ] && echo "depth + IMU (bims-odom, no mask)" || echo "depth only, no IMU (bims-odom --mode vision)")
	echo "| $what | $(traj "$DATA/odom_$m.txt") | $(measured "$DATA/odom_$m.csv") | $ms | $(jumps "$DATA/odom_$m.txt") |"
done
CONV=(--moving-value 255 --static-value 0 --ignore-values 150,50)
pct() { awk -v x="$1" 'BEGIN{ if (x == "nan" || x == "") print "-"; else printf "%.2f %%", 100 * x }'; }
SEG=""
for v in $VARIANTS; do
	out="$DATA/$v"
	rm -rf "$out"
	"$BIN/bims-run" "$CONFIG" "$RAWLOG" -o "$out" --variant "$v" -q > "$out.log" 2>&1 ||
		{ echo "stray_real.sh: bims-run --variant $v failed, see $out.log" >&2; exit 1; }
	ms=$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["stage_ms"]["egomotion"]["median"])' "$out/metrics.json")
	n=$(awk -F, 'NR > 1 {n++} NR > 1 && $3 >= 2048 && int($3 / 2048) % 2 == 1 {a++} END{printf "%d of %d", a, n}' "$out/frames.csv")
	echo "| bims-run --variant $v (masks fed back) | $(traj "$out/trajectory.txt") | $n | $ms | $(jumps "$out/trajectory.txt") |"
	fps=$(grep -o '"fps": [0-9.]*' "$out/metrics.json" | awk '{print $2}')
	if [ -d "$STRAY/masks_proxy" ]; then
		"$BIN/bims-eval" masks "$STRAY/masks_proxy" "$out/masks" "${CONV[@]}" --no-plots -q > "$out.eval" 2> "$out.eval.err" ||
			{ cat "$out.eval.err" >&2; exit 1; }
		read -r p r f i sm pf < <(awk '/^total precision/{t = $3 " " $5 " " $7 " " $9}
			/^total_static_as_moving/{a = $2} /^total_nothing_moving/{b = $5}
			END{print t, a, b}' "$out.eval")
		SEG+="| $v | $p | $r | $f | $i | $(pct "$sm") | $(pct "$pf") | $fps |"$'\n'
	else
		SEG+="| $v | - | - | - | - | - | - | $fps |"$'\n'
	fi
done
echo
echo "4. Segmentation vs masks_proxy, and speed (256x192)"
echo
echo "| variant | precision | recall | F1 | IoU | static called moving | same, frames without people | frames/s |"
echo "|---|---|---|---|---|---|---|---|"
printf "%s" "$SEG"
