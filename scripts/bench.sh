#!/usr/bin/env bash
# Runs the benchmarks of bench/ and writes one JSON object per measurement.
#   scripts/bench.sh [BUILD_DIR] [OUT_DIR] [-- extra bench_maps flags]
# Needs ../shared/data (Bonn depth frame) and builds a short VGA simulator
# sequence with bims-sim (config/sim/static_camera.ini, 6 frames).
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
BUILD="${1:-$ROOT/build}"
OUT="${2:-$BUILD/bench_results}"
shift $(( $# > 2 ? 2 : $# )) || true
[[ "${1:-}" == "--" ]] && shift
mkdir -p "$OUT"
cmake -S "$ROOT" -B "$BUILD" -DCMAKE_BUILD_TYPE=Release >/dev/null
targets=(bench_maps)
if [[ -f "$ROOT/libs/sim/CMakeLists.txt" ]]; then targets+=(bims-sim); fi
cmake --build "$BUILD" --target "${targets[@]}" -j2 >/dev/null

extra=()
if [[ -x "$BUILD/bin/bims-sim" ]]; then
  ini="$OUT/sim_vga.ini"
  sed -e 's/^frames=.*/frames=6/' "$ROOT/config/sim/static_camera.ini" > "$ini"
  "$BUILD/bin/bims-sim" "$ini" -o "$OUT/sim_vga.rawlog" --seed 1 --overwrite >/dev/null 2>&1
  extra+=("--sim_rawlog=$OUT/sim_vga.rawlog" "--sim_frame=3")
fi
"$BUILD/bin/bench_maps" "${extra[@]}" "$@" | tee "$OUT/bench_maps.jsonl"
echo "results: $OUT/bench_maps.jsonl" >&2

# A markdown summary: per cloud and voxel size, median ms (CPU ms) per frame.
python3 - "$OUT/bench_maps.jsonl" <<'PY' >&2
import json, sys
rows = [json.loads(l) for l in open(sys.argv[1]) if l.startswith("{")]
print("| measurement | cloud | voxel | ms median (wall) | ms median (CPU) |")
print("|---|---|---|---|---|")
for d in rows:
    n = d["name"].split("/")
    name = "/".join(x for x in n if x not in ("bonn", "sim") and not x.endswith("cm"))
    cloud = next((x for x in n if x in ("bonn", "sim")), "?")
    print("| %s | %s | %.2f | %.2f | %.2f |" % (name, cloud, d.get("voxel_m", 0),
          d.get("ms_median", float("nan")), d.get("cpu_ms_median", float("nan"))))
PY
