#!/bin/sh
# Egomotion variants on simulator presets, side by side (docs/journal/egomotion.md,
# "Egomotion"). Usage, from the repository root after building:
#   libs/ego/scripts/eval_presets.sh BUILD_DIR DATA_DIR [PRESET...]
# DATA_DIR/<preset>.rawlog and DATA_DIR/<preset>_gt/ must exist, made by
#   BUILD_DIR/bin/bims-sim config/sim/<preset>.ini -o DATA_DIR/<preset>.rawlog
# Writes DATA_DIR/<preset>_<mode>_<aid>.{txt,csv} and prints two markdown
# tables: ATE/RPE per preset and variant, and the fraction of features
# tracked within 2 px of the truth per angular-rate bin.
set -eu
BIN=$1/bin
DATA=$2
shift 2
PRESETS=${*:-"pendulum_slow fast_rotation static_camera mag_disturbance crowded"}
CFG=$(dirname "$0")/../../../config/default.ini

echo "| preset | variant | ATE RMSE [m] | RPE trans [m/s] | RPE rot [deg/s] | flagged | median ms (track+motion) |"
echo "|---|---|---|---|---|---|---|"
for p in $PRESETS; do
	for mode in imu vision; do
		for aid in true false; do
			out=$DATA/${p}_${mode}_${aid}
			log=$("$BIN/bims-odom" "$CFG" "$DATA/$p.rawlog" -o "$out.txt" \
				--calib "$DATA/${p}_gt/calibration.ini" --mode $mode \
				--gyro-aid $aid --gt "$DATA/${p}_gt/groundtruth.txt" \
				--csv "$out.csv" -q 2>&1)
			ev=$("$BIN/bims-eval" traj "$DATA/${p}_gt/groundtruth.txt" "$out.txt" --no-plot 2>&1)
			ate=$(echo "$ev" | awk '/^ate_rmse/{print $2}')
			rt=$(echo "$ev" | awk '/^rpe_trans_rmse/{print $2}')
			rr=$(echo "$ev" | awk '/^rpe_rot_rmse/{print $2}')
			fl=$(echo "$log" | sed -n 's/.*frames (\([0-9]*\) with the motion not measured).*/\1/p')
			ms=$(echo "$log" | sed -n 's/.*egomotion \([0-9.]*\) .*/\1/p')
			echo "| $p | $mode, gyro_aid=$aid | $ate | $rt | $rr | $fl | $ms |"
		done
	done
done

echo
echo "Fraction of tracked features within 2 px of the truth (imu mode), by true angular rate:"
echo
echo "| preset | gyro_aid | 0-30 deg/s | 30-60 | 60-120 | 120-200 | >200 |"
echo "|---|---|---|---|---|---|---|"
for p in $PRESETS; do
	for aid in true false; do
		awk -F, -v p="$p" -v aid="$aid" 'NR>1 && $11!="nan" && $12>0 {
			r=$11; b=(r<30)?1:(r<60)?2:(r<120)?3:(r<200)?4:5; d[b]+=$12; g[b]+=$13 }
			END { printf "| %s | %s |", p, aid;
			for (b=1;b<=5;b++) if (d[b]>0) printf " %.3f (%d) |", g[b]/d[b], d[b]; else printf " - |";
			printf "\n" }' "$DATA/${p}_imu_${aid}.csv"
	done
done
