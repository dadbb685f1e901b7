#!/usr/bin/env bash
# Soak: does bims-run's memory stay flat over a long run once the map has
# saturated? (issue 17; not part of CTest)
#
#   bench/soak.sh [BUILD_DIR] [FRAMES] [CONFIG] [INPUT.rawlog]
#
# Defaults: build, 3000 frames, config/default.ini. Without INPUT, simulates
# config/sim/pendulum_slow.ini for FRAMES frames at 320x240 (BIMS_SOAK_RES=
# 640x480 for VGA; gzip level 1). With INPUT (e.g. a real recording imported
# with bims-import-tum), gives it to bims-run as many times as FRAMES needs,
# each repeat shifted 1000 s later with MRPT's rawlog-edit (a jump forward,
# which bims-run takes as a new recording, keeping the map). Samples bims-run's resident memory (VmRSS)
# and peak (VmHWM) from /proc as frames.csv grows, and its own peak at the end
# (metrics.json), and prints one markdown row
# per checkpoint: 10 % of FRAMES, 50 %, 100 % (300 / 1500 / 3000 by
# default), plus the growth of the peak from the first checkpoint to the
# last.
set -euo pipefail
BUILD_DIR=${1:-build}
FRAMES=${2:-3000}
CONFIG=${3:-config/default.ini}
INPUT=${4:-}
RES=${BIMS_SOAK_RES:-320x240}
cd "$(dirname "$0")/.."
BIN="$BUILD_DIR/bin"
[ -x "$BIN/bims-run" ] || { echo "soak.sh: no $BIN/bims-run (build first)" >&2; exit 2; }
[[ $FRAMES =~ ^[0-9]+$ ]] && [ "$FRAMES" -ge 10 ] ||
	{ echo "soak.sh: FRAMES must be a whole number >= 10, got '$FRAMES'" >&2; exit 2; }
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT

INPUTS=()
if [ -z "$INPUT" ]; then
	echo "soak.sh: simulating $FRAMES frames at $RES ..." >&2
	sed -e "/^\[sim\]/a gz_level=1" config/sim/pendulum_slow.ini > "$TMP/scene.ini"
	"$BIN/bims-sim" "$TMP/scene.ini" -o "$TMP/in.rawlog" --max-frames "$FRAMES" \
		--resolution "$RES" -q > /dev/null
	INPUTS=("$TMP/in.rawlog")
	WHAT="simulated pendulum_slow $RES"
else
	[ -f "$INPUT" ] || { echo "soak.sh: $INPUT: no such file" >&2; exit 2; }
	INPUT=$(realpath "$INPUT")
	per=$("$BIN/bims-info" "$INPUT" | awk '/CObservation3DRangeScan/ {print $3; exit}')
	[[ ${per:-0} -gt 0 ]] || { echo "soak.sh: $INPUT: no RGB-D frames found by bims-info" >&2; exit 2; }
	command -v rawlog-edit > /dev/null || { echo "soak.sh: needs MRPT's rawlog-edit (mrpt-apps)" >&2; exit 2; }
	INPUTS=("$INPUT")
	for ((i = 1; i * per < FRAMES; i++)); do
		# each repeat 1000 s after the one before: bims-run drops frames that
		# go back in time, and takes a jump forward as a new recording
		echo "soak.sh: repeat $i of $INPUT, stamps + $((1000 * i)) s ..." >&2
		(cd "$TMP" && rawlog-edit --remap-timestamps "1;$((1000 * i))" -i "$INPUT" \
			-o "$TMP/repeat$i.rawlog" > /dev/null 2>&1) ||
			{ echo "soak.sh: rawlog-edit could not shift $INPUT" >&2; exit 1; }
		INPUTS+=("$TMP/repeat$i.rawlog")
	done
	WHAT="$(basename "$INPUT") x ${#INPUTS[@]}"
fi

"$BIN/bims-run" "$CONFIG" "${INPUTS[@]}" -o "$TMP/out" -q > "$TMP/log" 2>&1 &
pid=$!
checkpoints=($((FRAMES / 10)) $((FRAMES / 2)))
next=0
echo "| input | config | frames | VmRSS MiB | peak MiB | s since start |"
echo "|---|---|---|---|---|---|"
t0=$(date +%s.%N)
row() { printf "| %s | %s | %d | %s | %s | %.0f |\n" "$WHAT" "$(basename "$CONFIG")" "$1" "$2" "$3" \
	"$(echo "$(date +%s.%N) - $t0" | bc)"; }
first_peak=""
frames_done() { if [ -f "$TMP/out/frames.csv" ]; then echo $(($(wc -l < "$TMP/out/frames.csv") - 1)); else echo 0; fi; }
while [ $next -lt ${#checkpoints[@]} ] && kill -0 $pid 2> /dev/null; do
	done_frames=$(frames_done)
	if [ "$done_frames" -ge "${checkpoints[$next]}" ]; then
		rss=$(awk '/^VmRSS/ {printf "%.0f", $2 / 1024}' /proc/$pid/status)
		hwm=$(awk '/^VmHWM/ {printf "%.0f", $2 / 1024}' /proc/$pid/status)
		[ -n "$first_peak" ] || first_peak=$hwm
		row "$done_frames" "$rss" "$hwm"
		next=$((next + 1))
	fi
	sleep 0.05
done
# the end: bims-run's own peak (metrics.json, peak_resident_mib)
set +e
wait $pid
rc=$?
set -e
done_frames=$(frames_done)
if [ $rc -ne 0 ] || [ $next -lt ${#checkpoints[@]} ] || [ "$done_frames" -lt "$FRAMES" ]; then
	echo "soak.sh: bims-run ended (exit $rc) after $done_frames frames of $FRAMES:" >&2
	tail -5 "$TMP/log" >&2
	exit 1
fi
peak=$(sed -n 's/.*"peak_resident_mib": *\([0-9.]*\).*/\1/p' "$TMP/out/metrics.json" | awk '{printf "%.0f", $1}')
row "$done_frames" "-" "$peak"
echo
echo "peak growth from frame ${checkpoints[0]} to the end ($done_frames frames): $((peak - first_peak)) MiB"
