#!/usr/bin/env python3
"""The Python module's overhead: per-frame time of bims.Pipeline.process
called from Python against bims-run's, on the same frames with the same
configuration (a benchmark, not part of CTest; docs/python.md).

  PYTHONPATH=build/python bench/python_overhead.py [--build build]
      [--config config/default.ini] [--rawlog rawlogs/pendulum_slow.rawlog]
      [--repeats 3] [--set SECTION.KEY=VALUE ...]

bims-run's figure is its frames.csv ms_total (the pipeline's time for the
frame: decoding the scan, egomotion, flow, grids). Python's is the wall time
of each process() call (converting the arrays, the same pipeline, building
the Result), with the frames read beforehand (read_rawlog is not timed, as
bims-run reads on its own thread). Runs alternate (bims-run, Python,
bims-run, ...) so that a slower moment of the machine hits both. The look-ahead
of the observed flow ([pipeline] flow_lookahead) needs the next frame, which
process() does not have: it is switched off for both (--set overrides).
Prints one markdown table: median and p90 ms per frame, and the overhead
(Python's median / bims-run's - 1).
"""

import argparse
import csv
import os
import statistics
import subprocess
import sys
import tempfile
import time


def percentile(values, q):
    v = sorted(values)
    return v[min(len(v) - 1, int(round(q * (len(v) - 1))))]


def bims_run_ms(binary, config, rawlog):
    with tempfile.TemporaryDirectory() as out:
        subprocess.run([binary, config, rawlog, "-o", out, "-q"], check=True,
                       stdout=subprocess.DEVNULL)
        with open(os.path.join(out, "frames.csv")) as f:
            return [float(row["ms_total"]) for row in csv.DictReader(f)]


def python_ms(bims, cfg, frames):
    pipe = bims.Pipeline(cfg)
    wall, inside = [], []
    for f in frames:
        t0 = time.perf_counter()
        r = pipe.process(f.depth, rgb=f.rgb, stamp=f.stamp, imu=f.imu)
        wall.append(1e3 * (time.perf_counter() - t0))
        inside.append(r.times["total"])
    return wall, inside


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--build", default="build")
    ap.add_argument("--config", default="config/default.ini")
    ap.add_argument("--rawlog", default="rawlogs/pendulum_slow.rawlog")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--set", action="append", default=[], metavar="S.K=V")
    a = ap.parse_args()
    sys.path.insert(0, os.path.join(a.build, "python"))
    import bims

    overrides = ["pipeline.flow_lookahead=false"] + a.set
    cfg = bims.Config.from_file(a.config)
    for item in overrides:
        key, value = item.split("=", 1)
        section, key = key.split(".", 1)
        cfg.set(section, key, value)
    text = cfg.effective()  # what both runs read
    frames = list(bims.read_rawlog(a.rawlog, cfg))
    run_ms, py_wall, py_inside = [], [], []
    with tempfile.NamedTemporaryFile("w", suffix=".ini") as ini:
        ini.write(text)
        ini.flush()
        for _ in range(a.repeats):
            run_ms += bims_run_ms(os.path.join(a.build, "bin", "bims-run"),
                                  ini.name, a.rawlog)
            wall, inside = python_ms(bims, cfg, frames)
            py_wall += wall
            py_inside += inside
    base = statistics.median(run_ms)
    print(f"{len(frames)} frames x {a.repeats} runs of {a.rawlog}, "
          f"{a.config} with {', '.join(overrides)}\n")
    print("| | median ms/frame | p90 ms/frame | vs bims-run |")
    print("|---|---|---|---|")
    for name, v in (("bims-run (frames.csv ms_total)", run_ms),
                    ("Python process(), wall", py_wall),
                    ("Python, the pipeline's own total", py_inside)):
        m = statistics.median(v)
        print(f"| {name} | {m:.2f} | {percentile(v, 0.9):.2f} | "
              f"{100 * (m / base - 1):+.1f} % |")


if __name__ == "__main__":
    main()
