#!/usr/bin/env bash
# The cluster path of bims-sweep for real (docs/sweep.md, "Cluster mode"): a
# sweep of four 5-frame runs scored against the sample's ground truth, once
# locally (-j 2) and once through a cluster tool, then --collect; both
# results.csv must be the same but for the timing columns.
#
#   cluster_sweep.sh local    BIN_DIR SOURCE_DIR WORK_DIR
#       WORK_DIR/sweep.ini and the reference: bims-sweep -j 2 into
#       WORK_DIR/local (the fixture of the two below)
#   cluster_sweep.sh slurm    BIN_DIR SOURCE_DIR WORK_DIR CLUSTER_DIR
#       bims-sweep --slurm (one sbatch array job) on the single-node Slurm
#       that tests/cluster/slurm_cluster.sh started in CLUSTER_DIR
#   cluster_sweep.sh parallel BIN_DIR SOURCE_DIR WORK_DIR
#       GNU parallel -j 2 over --jobs-file's lines
#
# Exits 77 (skipped) with the reason when the cluster tool is not there.
set -euo pipefail
SKIP=77
mode=$1 bin=$2 src=$3 work=$4 cluster=${5:-}

case "$mode" in
  local) ;;
  slurm)
    if [ ! -f "$cluster/env" ]; then
      echo "SKIP: no Slurm cluster: $(cat "$cluster/skip" 2>/dev/null || echo "its fixture did not start one (see Slurm.ClusterStarts)")"
      exit $SKIP
    fi
    # shellcheck disable=SC1091
    . "$cluster/env" ;;
  parallel)
    if ! command -v parallel >/dev/null; then
      echo "SKIP: GNU parallel is not installed (Debian's parallel: scripts/install-deps.sh)"
      exit $SKIP
    fi ;;
  *) echo "usage: $0 local|slurm|parallel BIN_DIR SOURCE_DIR WORK_DIR [CLUSTER_DIR]" >&2; exit 2 ;;
esac

if [ "$mode" = local ]; then
  rm -rf "$work"
  mkdir -p "$work"
  cat > "$work/sweep.ini" <<INI
[sweep]
name = cluster path
configs = $src/config/default.ini
rawlogs = $src/rawlogs/pendulum_slow.rawlog
frames = 0:4
[grid]
grids.voxel_size = 0.05, 0.1
pipeline.variant = fused, bottom-only
[set]
pipeline.opencv_threads = 1
[truth]
masks = auto
trajectory = auto
INI

  echo "== local: bims-sweep -j 2"
  "$bin/bims-sweep" "$work/sweep.ini" -o "$work/local" -j 2 -q
  exit 0
fi

if [ ! -f "$work/local/results.csv" ]; then
  echo "FAIL: no reference $work/local/results.csv (see the fixture Sweep.ClusterReferenceRunsLocally)" >&2
  exit 1
fi
remote="$work/$mode"
rm -rf "$remote"
if [ "$mode" = parallel ]; then
  echo "== GNU parallel -j 2 over the jobs file"
  "$bin/bims-sweep" "$work/sweep.ini" -o "$remote" --jobs-file "$remote.jobs.txt"
  parallel -j 2 < "$remote.jobs.txt"
else
  echo "== Slurm: bims-sweep --slurm ($SLURM_CONF)"
  submitted=$("$bin/bims-sweep" "$work/sweep.ini" -o "$remote" --slurm)
  echo "$submitted"
  job=$(echo "$submitted" | sed -n 's/.*as Slurm array job \([0-9]*\).*/\1/p')
  [ -n "$job" ] || { echo "FAIL: no job id in bims-sweep's output" >&2; exit 1; }
  # the array's tasks leave the queue when done (bounded wait)
  deadline=$((SECONDS + 240))
  while [ -n "$(squeue -h -j "$job" -o '%i %T' 2>/dev/null)" ]; do
    if [ $SECONDS -ge $deadline ]; then
      echo "FAIL: job $job still queued or running after 240 s:" >&2
      squeue -j "$job" >&2 || true
      scancel "$job" || true
      tail -n 30 "$(dirname "$SLURM_CONF")"/log/*.log >&2 || true
      exit 1
    fi
    sleep 1
  done
  # each of the four tasks ran under Slurm (its output file), exit code 0
  n=$(ls "$remote/slurm" | grep -c "^${job}_[1-4]\.out$" || true)
  [ "$n" -eq 4 ] || { echo "FAIL: $n of 4 task outputs in $remote/slurm:" >&2; ls -l "$remote/slurm" >&2; exit 1; }
  grep -h "Launching batch job" "$(dirname "$SLURM_CONF")/log/slurmd.log" | tail -n 4
fi
echo "== bims-sweep --collect"
"$bin/bims-sweep" --collect "$remote"

/usr/bin/python3 - "$work/local/results.csv" "$remote/results.csv" <<'PY'
import csv, re, sys
# timing columns differ from run to run; every other one must not
timing = re.compile(r"^(exit_code|run_seconds|fps|wall_seconds|cpu_seconds|"
                    r"peak_resident_mib)$|^stage_ms\.|_fps$|_ms$|\.fps$")
def rows(path):
    with open(path, newline="") as f:
        r = list(csv.DictReader(f))
    return [{k: v for k, v in row.items() if not timing.search(k)} for row in r]
local, remote = rows(sys.argv[1]), rows(sys.argv[2])
assert len(local) == 4, f"{len(local)} local runs"
assert [r["status"] for r in local] == ["ok"] * 4, [r["status"] for r in local]
assert "masks.total.f1" in local[0] and local[0]["masks.total.f1"], "no F1 column"
assert "traj.ate.error_m.rmse" in local[0], "no ATE column"
if local != remote:
    for a, b in zip(local, remote):
        for k in sorted(set(a) | set(b)):
            if a.get(k) != b.get(k):
                print(f"{a.get('id')}: {k}: local {a.get(k)!r} != {b.get(k)!r}")
    sys.exit("FAIL: results.csv differ")
print(f"same results.csv ({len(local)} runs, {len(local[0])} columns compared; "
      f"F1 {', '.join(r['masks.total.f1'] for r in local)})")
PY
