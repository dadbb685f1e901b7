#!/usr/bin/env bash
# Egomotion in a crowd (issue 13's targets; not part of CTest, ~10 minutes):
# the trajectory of bims-run (the pipeline, with its moving masks fed back)
# and of bims-odom (egomotion alone, no mask: moving content left to the
# robust alignment) against ground truth, on the real Bonn slice (vision only, and with an
# IMU synthesised from the ground truth) and on every simulator preset at
# 640x480, beside OpenCV contrib's RgbdICPOdometry on the same frames.
#
#   bench/egomotion_real.sh [BUILD_DIR] [DATA_DIR] [PRESET...]
#
# BIMS_VARIANTS="fused bottom-only" runs bims-run once per variant (default:
# the config's own). BIMS_SET="section.key=value ..." overrides keys of every
# experiment file (e.g. BIMS_SET="anchor.mask_veto_consistent=0").
# Defaults: build, a temporary folder, every preset of config/sim/. The Bonn
# slice is read from ../shared/data/bonn_crowd_f150_349 (BIMS_BONN=DIR for
# another TUM/Bonn folder). Prints one markdown row per sequence and
# program: ATE RMSE [m] (SE(3)-aligned), RPE over 1 s (m/s, deg/s), frames
# anchored / failed / lost / relocalised, and the egomotion stage's median
# ms per frame (pipeline: on its thread, other stages on the other core).
set -euo pipefail
BUILD_DIR=${1:-build}
DATA=${2:-}
shift $(($# < 2 ? $# : 2))
cd "$(dirname "$0")/.."
BIN="$BUILD_DIR/bin"
PRESETS=${*:-$(ls config/sim/*.ini | xargs -n1 basename | sed 's/\.ini$//')}
BONN=${BIMS_BONN:-../shared/data/bonn_crowd_f150_349}
if [ -z "$DATA" ]; then
	DATA=$(mktemp -d)
	trap 'rm -rf "$DATA"' EXIT
fi
mkdir -p "$DATA"
for b in bims-run bims-odom bims-eval bims-sim bims-import-tum; do
	[ -x "$BIN/$b" ] || { echo "egomotion_real.sh: $BIN/$b missing (build first)" >&2; exit 1; }
done

traj() { # GT EST -> "ate rpe_t rpe_r"
	"$BIN/bims-eval" traj "$1" "$2" 2>/dev/null |
		awk '/^ate_rmse/{a=$2} /^rpe_trans_rmse/{t=$2} /^rpe_rot_rmse/{r=$2} END{printf "%s | %s | %s", a, t, r}'
}
# counts of anchored / anchor_failed / anchor_lost / anchor_relocalised
counts_run() { # frames.csv (ego_flags: kFlag* bits)
	local a=0 f=0 l=0 r=0 x
	while IFS=, read -r _ _ x _; do
		[[ $x =~ ^[0-9]+$ ]] || continue
		(( x & 2048 )) && a=$((a + 1))
		(( x & 4096 )) && f=$((f + 1))
		(( x & 16384 )) && l=$((l + 1))
		(( x & 65536 )) && r=$((r + 1))
	done < "$1"
	echo "$a / $f / $l / $r"
}
counts_odom() { # bims-odom CSV (flags as text)
	echo "$(grep -c '|anchored\|,anchored' "$1" || true) / $(grep -c anchor_failed "$1" || true) / $(grep -c anchor_lost "$1" || true) / $(grep -c anchor_relocalised "$1" || true)"
}
stage_ms() { # metrics.json -> egomotion median
	python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["stage_ms"]["egomotion"]["median"])' "$1"
}
odom_ms() { # bims-odom summary line -> egomotion median
	sed -n 's/.*egomotion \([0-9.]*\).*/\1/p'
}

# one experiment file per sequence: BASE with [odometry] mode = MODE, the
# R_IC and time offset of CALIB (a bims-sim calibration.ini, or empty) and
# no map exports (they do not change the trajectory)
config() { # BASE MODE CALIB OUT
	local ric="" off=""
	if [ -n "$3" ]; then
		ric=$(awk -F= '/^R_IC=/{print $2}' "$3")
		off=$(awk -F= '/^time_offset_s=/{print $2}' "$3")
	fi
	awk -v ric="$ric" -v off="$off" -v mode="$2" '
		/^\[/ {sec=$0}
		sec=="[calibration]" && /^R_IC *=/ && ric!="" {print "R_IC=" ric; next}
		sec=="[calibration]" && /^time_offset_s *=/ && off!="" {print "time_offset_s=" off; next}
		sec=="[odometry]" && /^mode *=/ {next}
		sec=="[output]" && /^(moving_ply|static_map|labelled_rawlog) *=/ {sub(/=.*/, "=false")}
		{print}
		/^\[odometry\]/ {print "mode=" mode; seen=1}
		END {if (!seen) printf "\n[odometry]\nmode=%s\n", mode}' "$1" > "$4"
	local kv sec key val
	for kv in ${BIMS_SET:-}; do
		sec=${kv%%.*}; key=${kv#*.}; val=${key#*=}; key=${key%%=*}
		awk -v sec="[$sec]" -v key="$key" -v val="$val" '
			/^\[/ {s=$0}
			s==sec && $0 ~ "^" key " *=" {next}
			{print}
			$0==sec {print key "=" val; done=1}
			END {if (!done) printf "\n%s\n%s=%s\n", sec, key, val}' "$4" > "$4.tmp" && mv "$4.tmp" "$4"
	done
}

echo "| sequence | program | mode | ATE RMSE [m] | RPE [m/s] | RPE [deg/s] | anchored / failed / lost / relocalised | egomotion ms (median) |"
echo "|---|---|---|---|---|---|---|---|"
run_all() { # NAME RAWLOG GT BASECFG CALIB MODES
	local name=$1 rl=$2 gt=$3 base=$4 calib=$5 modes=$6 m cfg out
	for m in $modes; do
		cfg="$DATA/${name}_$m.ini"
		config "$base" "$m" "$calib" "$cfg"
		for v in ${BIMS_VARIANTS:-default}; do
			out="$DATA/${name}_${m}_${v}_run"
			"$BIN/bims-run" "$cfg" "$rl" -o "$out" --overwrite -q \
				$([ "$v" = default ] || echo "--variant $v") > "$out.log" 2>&1
			echo "| $name | bims-run$([ "$v" = default ] || echo " --variant $v") | $m | $(traj "$gt" "$out/trajectory.txt") | $(counts_run "$out/frames.csv") | $(stage_ms "$out/metrics.json") |"
		done
		ms=$("$BIN/bims-odom" "$cfg" "$rl" -o "$DATA/${name}_${m}_odom.txt" --csv "$DATA/${name}_${m}_odom.csv" -q 2>&1 | odom_ms)
		echo "| $name | bims-odom | $m | $(traj "$gt" "$DATA/${name}_${m}_odom.txt") | $(counts_odom "$DATA/${name}_${m}_odom.csv") | $ms |"
	done
	if [ -x "$BIN/rgbd_odometry_baseline" ]; then
		ms=$("$BIN/rgbd_odometry_baseline" "$base" "$rl" -o "$DATA/${name}_cv.txt" | sed -n 's/.*median \([0-9.]*\).*/\1/p')
		echo "| $name | OpenCV RgbdICPOdometry | frame to frame | $(traj "$gt" "$DATA/${name}_cv.txt") | - | $ms |"
	fi
}

if [ -d "$BONN" ]; then
	"$BIN/bims-import-tum" "$BONN" -o "$DATA/bonn.rawlog" --config config/bonn.ini --bonn-gt > /dev/null 2>&1
	"$BIN/bims-import-tum" "$BONN" -o "$DATA/bonn_imu.rawlog" --config config/bonn.ini --bonn-gt --synth-imu > /dev/null 2>&1
	run_all bonn "$DATA/bonn.rawlog" "$DATA/bonn_gt/groundtruth.txt" config/bonn.ini "" vision
	run_all bonn_synthetic_imu "$DATA/bonn_imu.rawlog" "$DATA/bonn_imu_gt/groundtruth.txt" config/bonn.ini "$DATA/bonn_imu_gt/calibration.ini" imu
else
	echo "egomotion_real.sh: $BONN not found, Bonn rows skipped" >&2
fi
for p in $PRESETS; do
	[ -f "$DATA/$p.rawlog" ] || "$BIN/bims-sim" "config/sim/$p.ini" -o "$DATA/$p.rawlog" --seed 1 -q > /dev/null 2>&1
	run_all "$p" "$DATA/$p.rawlog" "$DATA/${p}_gt/groundtruth.txt" config/default.ini "$DATA/${p}_gt/calibration.ini" "imu vision"
done
