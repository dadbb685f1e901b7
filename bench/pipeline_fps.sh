#!/usr/bin/env bash
# End-to-end speed of bims-run at 640x480 and 320x240 on simulator data
# (not part of CTest).
#
#   bench/pipeline_fps.sh [BUILD_DIR] [FRAMES] [REPEATS] [VARIANTS]
#
# Defaults: build, 120 frames, 1 run, "fused fused-raycast". Simulates
# config/sim/pendulum_slow.ini (--seed 1) at both resolutions, runs bims-run
# with config/default.ini and all its default outputs, and prints one
# markdown row per run: per-stage median / p95 ms from metrics.json (flow: on
# the run's thread; observed flow: on the flow thread; grids: on the run's
# thread, waiting for the cloud build and the tiers; cloud build: on the
# cloud thread), frames/s
# end to end (bims-run's own figure: reading, every frame, every output) and
# of the whole process (start to exit), CPU time per frame (all threads), peak
# resident memory (MiB), and the load average before the run. BIMS_RUN=/path/to/bims-run measures
# another binary (stages it does not report print as "-"), BIMS_CONFIG=X.ini
# another experiment file (e.g. the one of that binary's version).
# BIMS_INPUT_GZ=N writes the simulated input with gzip level N (default 0:
# plain, as bims-grab records; inflating gzip costs ~20 ms of CPU per
# 640x480 frame on the reading thread). The input has no pixel labels, as a
# recording of a sensor (the simulator's ground-truth labels, one byte per
# pixel read through MRPT's archive, cost ~2 ms of reading CPU per frame);
# BIMS_INPUT_LABELS=1 keeps them.
set -euo pipefail
BUILD_DIR=${1:-build}
FRAMES=${2:-120}
REPEATS=${3:-1}
VARIANTS=${4:-fused fused-raycast}
cd "$(dirname "$0")/.."
BIN="$BUILD_DIR/bin"
RUN=${BIMS_RUN:-$BIN/bims-run}
CONFIG=${BIMS_CONFIG:-config/default.ini}
GZ=${BIMS_INPUT_GZ:-0}
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
LABELS=${BIMS_INPUT_LABELS:-0}
sed -e "/^\[sim\]/a gz_level=$GZ\npixel_labels=$([ "$LABELS" = 1 ] && echo true || echo false)" \
  config/sim/pendulum_slow.ini > "$TMP/scene.ini"

# "median / p95" of a stage in metrics.json, "-" when absent
stage() {
  python3 -c 'import json, sys
s = json.load(open(sys.argv[2]))["stage_ms"].get(sys.argv[1])
print("%.2f / %.2f" % (s["median"], s["p95"]) if s else "-", end="")' "$1" "$2"
}
field() { python3 -c 'import json, sys; print(json.load(open(sys.argv[2]))[sys.argv[1]])' "$1" "$2"; }
load() { cut -d' ' -f1 /proc/loadavg; }

echo "bims-run: $RUN, $CONFIG; input gzip level $GZ, pixel labels $LABELS; $(nproc) cores; $(date -u '+%Y-%m-%d %H:%M UTC')"
echo
echo "| resolution, variant | read | egomotion | flow | observed flow | grids | cloud build | pipeline total | outputs | frames/s end to end | frames/s process | CPU ms/frame | peak MiB | load |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for res in 640x480 320x240; do
  "$BIN/bims-sim" "$TMP/scene.ini" -o "$TMP/$res.rawlog" \
    --max-frames "$FRAMES" --resolution "$res" --seed 1 -q > /dev/null 2>&1
  for v in $VARIANTS; do
    for ((k = 0; k < REPEATS; k++)); do
      out="$TMP/out_${res}_$v"
      rm -rf "$out"
      l=$(load)
      t0=$(date +%s.%N)
      "$RUN" "$CONFIG" "$TMP/$res.rawlog" -o "$out" --variant "$v" \
        -q > "$TMP/log" 2>&1 || { cat "$TMP/log"; exit 1; }
      t1=$(date +%s.%N)
      m="$out/metrics.json"
      n=$(field frames_processed "$m")
      cpu=$(field cpu_seconds "$m")
      printf "| %s %s | %s | %s | %s | %s | %s | %s | %s | %s | %.1f | %.1f | %s | %s | %s |\n" \
        "$res" "$v" "$(stage read "$m")" "$(stage egomotion "$m")" \
        "$(stage flow "$m")" "$(stage flow_observed "$m")" \
        "$(stage grids "$m")" "$(stage grids_cloud "$m")" "$(stage total "$m")" \
        "$(stage outputs "$m")" "$(field fps "$m")" \
        "$(echo "$n $t0 $t1" | awk '{print $1 / ($3 - $2)}')" \
        "$(if [ -n "$cpu" ]; then echo "$cpu $n" | awk '{printf "%.1f", 1000 * $1 / $2}'; else echo -; fi)" \
        "$(field peak_resident_mib "$m" | awk '{printf "%.0f", $1} END {if (NR == 0) printf "-"}')" \
        "$l"
    done
  done
done
