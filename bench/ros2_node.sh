#!/usr/bin/env bash
# bims-ros2 at a driver's rate (issue 53's keep-up target; not part of CTest,
# ~1 minute): simulates config/sim/pendulum_slow.ini at RES (30 Hz depth and
# colour, 100 Hz IMU), plays it in real time as realsense-ros 4.x's topics
# (test_ros2_play --realtime: every observation at its own time in the
# recording, never waiting for the node) to bims-ros2 on the loopback of a
# private network namespace (unshare -rn: nothing leaves the machine), and
# prints
#   - the depth images sent, the masks received, the frames the node dropped
#     (its own count: arrived faster than it processed them, the oldest
#     waiting dropped), the share dropped;
#   - the mask latency: the depth image sent to its mask received (steady
#     clock; DDS both ways included, so an upper bound of the node's depth
#     stamp to publish): median, p95, max [ms].
#
#   bench/ros2_node.sh [BUILD_DIR] [RES] [FRAMES] [VARIANT] [SECTION.KEY=VALUE...]
#
# Defaults: build, 640x480, 300 frames (10 s), fused; each SECTION.KEY=VALUE
# is set in the experiment (config/default.ini with the simulation's
# [calibration]), e.g. pipeline.flow_lookahead=false. The load average before
# the run is printed too: the node shares the 2 cores with the player.
set -euo pipefail
BUILD_DIR=${1:-build}
RES=${2:-640x480}
FRAMES=${3:-300}
VARIANT=${4:-fused}
shift $(($# < 4 ? $# : 4))
cd "$(dirname "$0")/.."
BIN="$BUILD_DIR/bin"
for b in bims-sim bims-ros2 test_ros2_play; do
	[ -x "$BIN/$b" ] || { echo "ros2_node.sh: $BIN/$b missing (build first)" >&2; exit 1; }
done
unshare -rn true 2> /dev/null ||
	{ echo "ros2_node.sh: unshare -rn refused: no private network namespace here" >&2; exit 1; }
DATA=$(mktemp -d)
trap 'rm -rf "$DATA"' EXIT
"$BIN/bims-sim" config/sim/pendulum_slow.ini -o "$DATA/in.rawlog" -r "$RES" \
	--max-frames "$FRAMES" --seed 1 -q > "$DATA/sim.log" 2>&1 ||
	{ cat "$DATA/sim.log" >&2; exit 1; }
. scripts/sim_experiment.sh
sim_experiment_config "$DATA/in_gt/calibration.ini" "$DATA/exp.ini" pipeline.variant="$VARIANT" "$@"
printf '\n[ros2]\nmag_topic = /camera/camera/mag\ndepth_units = 0.001\nrange_units = 0.001\n' >> "$DATA/exp.ini"
cat > "$DATA/loopback.sh" << EOF
ip link set lo up && ip link set lo multicast on && ip route add 224.0.0.0/4 dev lo || exit 90
export CYCLONEDDS_URI='<CycloneDDS><Domain><General><Interfaces><NetworkInterface name="lo" multicast="true"/></Interfaces></General></Domain></CycloneDDS>'
'$BIN/bims-ros2' '$DATA/exp.ini' > '$DATA/node.log' 2>&1 &
NODE=\$!
'$BIN/test_ros2_play' '$DATA/in.rawlog' '$DATA/play' --realtime --stop-pid \$NODE \
	--mag-topic /camera/camera/mag > '$DATA/play.log' 2>&1
kill -INT \$NODE 2> /dev/null
wait \$NODE
EOF
LOAD=$(cut -d' ' -f1 /proc/loadavg)
unshare -rn sh "$DATA/loopback.sh" ||
	{ echo "ros2_node.sh: the run failed:" >&2; cat "$DATA/node.log" "$DATA/play.log" >&2; exit 1; }
DROPPED=$(grep -o '[0-9]* dropped' "$DATA/node.log" | tail -1 | cut -d' ' -f1)
[ $# -gt 0 ] && echo "settings: $*"
echo "| resolution | variant | depth images sent | masks received | dropped by the node | dropped [%] | latency median / p95 / max [ms] | load before |"
echo "|---|---|---|---|---|---|---|---|"
python3 - "$DATA/play/times.csv" "$RES" "$VARIANT" "${DROPPED:-?}" "$LOAD" << 'PY'
import sys
rows = [l.strip().split(",") for l in open(sys.argv[1]) if l.strip()]
res, var, dropped, load = sys.argv[2:6]
lat = sorted((int(r[3]) - int(r[2])) / 1e6 for r in rows if int(r[3]) >= 0)
n, m = len(rows), len(lat)
if m == 0:
    print(f"| {res} | {var} | {n} | 0 | {dropped} | - | - | {load} |")
else:
    q = lambda p: lat[min(m - 1, int(p * m))]
    print(f"| {res} | {var} | {n} | {m} | {dropped} | {100 * (n - m) / n:.1f} "
          f"| {q(0.5):.1f} / {q(0.95):.1f} / {lat[-1]:.1f} | {load} |")
PY
