#!/usr/bin/env bash
# Segmentation on a real recording against per-pixel labels (issue 14; not
# part of CTest, ~2 minutes): imports the Bonn crowd slice (no IMU), runs
# bims-run with CONFIG for every variant, scores each run's masks against
# the slice's masks_proxy labels (255 moving, 0 static, 150 and 50 not
# scored; paired by time stamp) and prints one markdown row per variant:
# precision, recall, F1, IoU of "moving", the share of labelled-static
# pixels called moving (all frames, and the frames without a moving label),
# and bims-run's frames/s end to end.
#
#   bench/segmentation_real.sh [BUILD_DIR] [DATA_DIR] [CONFIG] [VARIANT...]
#
# Defaults: build, a temporary folder, config/bonn.ini, the four variants.
# BIMS_BONN=DIR reads another TUM/Bonn folder with a masks_proxy/ of the same
# convention. BIMS_STRIP=OUT.png also writes the fused run's overlays of
# frames BIMS_STRIP_FRAMES (default 20,80,120,160,199) side by side (TP green,
# FP red, FN blue, not scored grey, over the RGB image).
set -euo pipefail
BUILD_DIR=${1:-build}
DATA=${2:-}
CONFIG=${3:-config/bonn.ini}
shift $(($# < 3 ? $# : 3))
VARIANTS=${*:-bottom-only flow-only fused fused-raycast}
cd "$(dirname "$0")/.."
BIN="$BUILD_DIR/bin"
BONN=${BIMS_BONN:-../shared/data/bonn_crowd_f150_349}
LABELS="$BONN/masks_proxy"
for b in bims-run bims-eval bims-import-tum; do
	[ -x "$BIN/$b" ] || { echo "segmentation_real.sh: $BIN/$b missing (build first)" >&2; exit 1; }
done
[ -d "$LABELS" ] || { echo "segmentation_real.sh: $LABELS not found" >&2; exit 1; }
if [ -z "$DATA" ]; then
	DATA=$(mktemp -d)
	trap 'rm -rf "$DATA"' EXIT
fi
mkdir -p "$DATA"
RAWLOG="$DATA/$(basename "$BONN").rawlog"
[ -f "$RAWLOG" ] || "$BIN/bims-import-tum" "$BONN" -o "$RAWLOG" --config "$CONFIG" -q > /dev/null
CONV=(--moving-value 255 --static-value 0 --ignore-values 150,50)
pct() { # share -> "12.34 %"
	awk -v x="$1" 'BEGIN{ if (x == "nan") print "nan"; else printf "%.2f %%", 100 * x }'
}
echo "| variant | precision | recall | F1 | IoU | static called moving | same, frames without people | frames/s |"
echo "|---|---|---|---|---|---|---|---|"
for v in $VARIANTS; do
	out="$DATA/$v"
	rm -rf "$out"
	"$BIN/bims-run" "$CONFIG" "$RAWLOG" -o "$out" --variant "$v" -q > "$out.log" 2>&1 ||
		{ echo "segmentation_real.sh: bims-run --variant $v failed, see $out.log" >&2; exit 1; }
	"$BIN/bims-eval" masks "$LABELS" "$out/masks" "${CONV[@]}" --no-plots -q > "$out.eval" 2> "$out.eval.err" ||
		{ cat "$out.eval.err" >&2; exit 1; }
	if [ -n "${BIMS_STRIP:-}" ] && [ "$v" = fused ]; then
		# (the rawlog only gives the overlays their RGB background)
		"$BIN/bims-eval" masks "$LABELS" "$out/masks" "${CONV[@]}" --no-plots -q \
			--strip "$BIMS_STRIP" --strip-frames "${BIMS_STRIP_FRAMES:-20,80,120,160,199}" \
			--depth-valid "$RAWLOG" --voxel-size 0 > /dev/null 2>> "$out.eval.err" ||
			{ cat "$out.eval.err" >&2; exit 1; }
	fi
	# precision recall F1 IoU, static called moving (all frames, frames
	# without a moving label) from bims-eval's total lines
	read -r p r f i sm pf < <(awk '/^total precision/{t = $3 " " $5 " " $7 " " $9}
		/^total_static_as_moving/{a = $2} /^total_nothing_moving/{b = $5}
		END{print t, a, b}' "$out.eval")
	fps=$(grep -o '"fps": [0-9.]*' "$out/metrics.json" | awk '{print $2}')
	echo "| $v | $p | $r | $f | $i | $(pct "$sm") | $(pct "$pf") | $fps |"
done
