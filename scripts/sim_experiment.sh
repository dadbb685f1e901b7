# shellcheck shell=bash
# Sourced by the simulator benchmarks (scripts/segmentation_table.sh,
# bench/depth_only_sim.sh), from the repository root:
#
#   sim_presets [PRESET...]   the presets given, else every config/sim/*.ini
#   sim_data_dir              DATA made (a temporary folder removed at exit
#                             when DATA is unset)
#
#   sim_experiment_config CALIB.ini OUT.ini [SECTION.KEY=VALUE...]
#
# writes config/default.ini to OUT.ini with R_IC and time_offset_s of
# [calibration] taken from CALIB.ini (a simulation's ground truth), the heavy
# per-frame outputs off (moving_ply, static_map, labelled_rawlog) and each
# SECTION.KEY given set to VALUE (keys that config/default.ini holds).
sim_presets() {
	if [ $# -gt 0 ]; then
		echo "$*"
	else
		ls config/sim/*.ini | xargs -n1 basename | sed 's/\.ini$//'
	fi
}

sim_data_dir() {
	if [ -z "${DATA:-}" ]; then
		DATA=$(mktemp -d)
		trap 'rm -rf "$DATA"' EXIT
	fi
	mkdir -p "$DATA"
}

sim_experiment_config() {
	local calib=$1 out=$2
	shift 2
	local ric off sets
	ric=$(awk -F= '/^R_IC=/{print $2}' "$calib")
	off=$(awk -F= '/^time_offset_s=/{print $2}' "$calib")
	sets="calibration.R_IC=$ric;calibration.time_offset_s=$off"
	for kv in "$@"; do sets="$sets;$kv"; done
	awk -v sets="$sets" '
		BEGIN {
			n = split(sets, kv, ";")
			for (i = 1; i <= n; i++) {
				e = index(kv[i], "=")
				set[substr(kv[i], 1, e - 1)] = substr(kv[i], e + 1)
			}
		}
		/^\[/ { sec = substr($0, 2, index($0, "]") - 2) }
		!/^[[#]/ && index($0, "=") {
			key = substr($0, 1, index($0, "=") - 1)
			if ((sec "." key) in set) { print key "=" set[sec "." key]; next }
		}
		sec == "output" && /^(moving_ply|static_map|labelled_rawlog)=/ { sub(/=.*/, "=false") }
		{ print }' config/default.ini > "$out"
}
