"""The Python API's argument checks under hostile arguments (issue 55): a
seeded, deterministic stream of wrong types, NaN, infinities, huge,
negative and empty values, wrong dtypes and shapes thrown at every public
call. Each call must return or raise a clean Python exception (TypeError,
ValueError, OSError, KeyError, RuntimeError) with a message of ours: no
crash, no hang, no pybind11 "Unable to cast", no C++ or OpenCV internals.

The cases run in a child process (python3 fuzz_python_api.py --child SEED
N LOG), which writes each case to LOG before running it: a crash or a hang
fails the test naming the case. BIMS_FUZZ_SEED and BIMS_FUZZ_CASES choose
another stream (CTest runs the default one)."""

import math
import os
import pathlib
import random
import subprocess
import sys
import tempfile
import unittest
import warnings

SOURCE = os.environ.get("BIMS_SOURCE_DIR", os.getcwd())
SAMPLE = os.path.join(SOURCE, "rawlogs", "pendulum_slow.rawlog")
CONFIG = os.path.join(SOURCE, "config", "default.ini")
SEED = int(os.environ.get("BIMS_FUZZ_SEED", "55"))
CASES = int(os.environ.get("BIMS_FUZZ_CASES", "3000"))
VERBOSE = bool(os.environ.get("BIMS_FUZZ_VERBOSE"))

#: the exceptions a bad argument may raise (RawlogError is an OSError,
#: ConfigError and UsageError are ValueErrors)
CLEAN = (TypeError, ValueError, OSError, KeyError, RuntimeError)
#: what no message of ours says
NOT_OURS = (
    "Unable to cast",
    "std::",
    "cv::",
    "OpenCV(",
    "basic_string",
    "vector::",
    "Assertion",
    "bad_alloc",
    "(-215",
)


class HostileError(Exception):
    """What Hostile's conversions raise: passed on as it is, it is clean."""


class Hostile:
    """An object whose conversions raise."""

    def __float__(self):
        raise HostileError("no float here")

    def __index__(self):
        raise HostileError("no index here")

    def __fspath__(self):
        return 42  # not a path


def hostile_values(rng, np):
    """Scalars and objects of every wrong kind."""
    return [
        None,
        True,
        0,
        -1,
        2**70,
        1e300,
        -1e300,
        1e-300,
        float("nan"),
        float("inf"),
        -float("inf"),
        np.float32("nan"),
        np.float64(1e6),
        np.int64(-5),
        "",
        "x",
        "0.001",
        "\0",
        b"abc",
        [],
        [1, 2, 3],
        [[1, 2, 3], [4, 5, 6], [7, 8, 9]],
        {},
        {"a": 1},
        object(),
        Hostile(),
        pathlib.Path(""),
        pathlib.Path("no/such/place"),
        lambda *a: None,
        np.array(3.0),
        np.zeros(0),
        rng.random(),
    ]


def hostile_array(rng, np):
    """An array of a random dtype, shape and contents."""
    dtype = rng.choice(
        [np.uint8, np.uint16, np.int16, np.int32, np.float32, np.float64,
         np.bool_, np.complex64, object]
    )
    shape = rng.choice(
        [(0,), (0, 0), (1, 1), (2, 2), (3, 3), (4, 4), (7,), (1, 100000),
         (100000, 1), (8, 40), (24, 32), (48, 64), (60, 80), (48, 64, 3),
         (48, 64, 4), (2, 3, 4, 5), (3, 7), (3, 10), (3, 14), (0, 7), (5, 7)]
    )
    kind = rng.choice(["zeros", "ones", "random", "huge", "negative", "nan",
                       "inf", "mixed"])
    size = int(np.prod(shape))
    if dtype is object:
        a = np.empty(shape, dtype=object)
        a.flat[:] = [rng.choice([None, "x", 1.5]) for _ in range(size)]
        return a
    if kind == "zeros":
        a = np.zeros(shape)
    elif kind == "ones":
        a = np.ones(shape)
    elif kind == "random":
        a = np.asarray([rng.random() * 3 for _ in range(min(size, 4096))]
                       + [1.0] * max(0, size - 4096)).reshape(shape)
    elif kind == "huge":
        a = np.full(shape, 1e300)
    elif kind == "negative":
        a = -np.ones(shape)
    elif kind == "nan":
        a = np.full(shape, np.nan)
    elif kind == "inf":
        a = np.full(shape, np.inf)
    else:
        a = np.ones(shape)
        if size:
            flat = a.reshape(-1)
            for v in (np.nan, np.inf, -np.inf, 1e300, -7.0, 1e6, 0.0):
                flat[rng.randrange(size)] = v
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        a = a.astype(dtype)
    if rng.random() < 0.2 and a.ndim >= 2 and a.shape[1] > 1:
        a = a[:, ::2]  # not contiguous
    return a


def child(seed, cases, log_path):
    import numpy as np

    import bims

    warnings.simplefilter("ignore")
    rng = random.Random(seed)
    frames = [f for _, f in zip(range(3), bims.read_rawlog(SAMPLE))]
    cfg = bims.Config.from_file(CONFIG)
    work = tempfile.mkdtemp(prefix="bims_fuzz_")
    os.chdir(work)  # a path written by mistake lands here (checked)
    empty_dir = os.path.join(work, "empty_dir")
    os.mkdir(empty_dir)
    empty_file = os.path.join(work, "empty.rawlog")
    open(empty_file, "w").close()
    state = {"pipe": bims.Pipeline(cfg), "stamp": 1.0, "calls": 0}

    def value():
        r = rng.random()
        if r < 0.55:
            return rng.choice(hostile_values(rng, np))
        if r < 0.9:
            return hostile_array(rng, np)
        return rng.choice([SAMPLE, empty_file, empty_dir, "no_such.rawlog",
                           os.path.join(empty_dir, "x.rawlog")])

    def valid(name, f):
        if name == "depth":
            return f.depth
        if name == "rgb":
            return f.rgb
        if name == "stamp":
            state["stamp"] += 1.0
            return state["stamp"]
        if name == "imu":
            imu = f.imu.copy()
            imu[:, 0] = state["stamp"] - 0.5 + 0.01 * np.arange(len(imu))
            return imu
        if name == "K":
            return f.K
        return None  # depth_units

    def near_valid(name, f):
        """A valid argument with hostile contents: extreme pixels, times,
        intrinsics and units that pass the type checks."""
        extreme = rng.choice([0.0, 1e-300, 1e-30, 1e-3, 65535.0, 1e6, 1e30,
                              1e300, -1e300, -1.0, float("inf"), float("nan")])
        if name == "depth":
            if rng.random() < 0.5:
                d = np.array(f.depth, dtype=np.uint16)
                if rng.random() < 0.3:
                    d[:] = rng.choice([0, 1, 65535])
            else:
                d = f.depth.astype(np.float32) * np.float32(0.001)
                with np.errstate(all="ignore"):
                    for _ in range(rng.choice([1, 5, 500])):
                        d[rng.randrange(d.shape[0]), rng.randrange(d.shape[1])] = extreme
            if rng.random() < 0.2:  # another size
                h, w = rng.randrange(1, d.shape[0]), rng.randrange(1, d.shape[1])
                d = np.ascontiguousarray(d[:h, :w])
            return d
        if name == "rgb":
            return rng.choice([
                f.rgb, np.zeros_like(f.rgb), np.full(f.rgb.shape[:2], 255, np.uint8),
                np.ascontiguousarray(f.rgb[:-1]), None])
        if name == "stamp":
            return rng.choice([state["stamp"] + 1e-9, state["stamp"] + 1e6,
                               1e300, -1e300, 1e18, state["stamp"], 0.0, extreme])
        if name == "imu":
            imu = valid("imu", f)
            with np.errstate(all="ignore"):
                for _ in range(rng.choice([1, 3])):
                    imu[rng.randrange(len(imu)), rng.randrange(1, 14)] = extreme
                if rng.random() < 0.2:
                    imu[rng.randrange(len(imu)), 0] = extreme
            return imu
        if name == "K":
            K = np.array(f.K, dtype=np.float64)
            K[rng.choice([(0, 0), (1, 1), (0, 2), (1, 2), (0, 1)])] = extreme
            return K
        return rng.choice([extreme, 1e-30, 1e30, 0.001, 1])

    def pipe():
        state["calls"] += 1
        if state["calls"] % 40 == 0:
            state["pipe"] = bims.Pipeline(cfg)
        return state["pipe"]

    def process_case():
        f = rng.choice(frames)
        names = ["depth", "rgb", "stamp", "imu", "K", "depth_units"]
        args = {n: valid(n, f) for n in names}
        for n in rng.sample(names, rng.choice([1, 1, 2])):
            args[n] = value() if rng.random() < 0.4 else near_valid(n, f)
        def go():
            r = pipe().process(**args)
            state["stamp"] = max(state["stamp"], r.stamp)  # the next after it
            if not (np.isfinite(r.pose).all() and np.isfinite(r.motion).all()):
                raise AssertionError("a pose not finite, without an error")

        return "Pipeline.process(%s)" % describe(args), go

    def depth_array_case():
        f = rng.choice(frames)
        a = f.depth if rng.random() < 0.5 else value()
        K = f.K if rng.random() < 0.5 else value()
        units = value() if rng.random() < 0.7 else None
        state["stamp"] += 1.0
        t = state["stamp"]

        def go():
            d = bims.DepthArray(a, K=K, units=units)
            r = pipe().process(d, stamp=t)
            state["stamp"] = max(state["stamp"], r.stamp)

        return "DepthArray(%s)" % describe(dict(a=a, K=K, units=units)), go

    def query_case():
        v = value()
        p = pipe()
        which = rng.choice(["occupied_voxels", "static_voxels",
                            "save_static_map", "save_static_map_p"])
        if which == "save_static_map":
            return "save_static_map(%s)" % describe(v), lambda: p.save_static_map(v)
        if which == "save_static_map_p":
            return ("save_static_map('m.ply', %s)" % describe(v),
                    lambda: p.save_static_map("m.ply", v))
        return "%s(%s)" % (which, describe(v)), lambda: getattr(p, which)(v)

    def config_case():
        which = rng.choice(["from_file", "from_string", "get", "set", "pipeline"])
        a, b, c = value(), value(), value()
        if which == "from_file":
            return "Config.from_file(%s)" % describe(a), lambda: bims.Config.from_file(a)
        if which == "from_string":
            text = rng.choice([
                a, "", "[grids]\nvoxel_size = nan\n", "[grids]\nvoxel_size = 1e300\n",
                "[anchor]\ncoarsest_level = -3\n", "[[[\n", "x = 1\n",
                "[input]\nimage_max_side = 0\n", "\0\0\0",
            ])
            return ("Config.from_string(%s)" % describe(text),
                    lambda: bims.Config.from_string(text))
        if which == "get":
            sec = rng.choice([a, "grids", "anchor"])
            key = rng.choice([b, "voxel_size", "enable"])
            return ("Config.get(%s, %s)" % (describe(sec), describe(key)),
                    lambda: bims.Config().get(sec, key))
        if which == "set":
            sec = rng.choice([a, "grids", "flow", "input"])
            key = rng.choice([b, "voxel_size", "max_depth_m", "image_max_side"])
            return ("Config.set(%s, %s, %s)" % (describe(sec), describe(key), describe(c)),
                    lambda: bims.Config().set(sec, key, c))
        return "Pipeline(%s)" % describe(a), lambda: bims.Pipeline(a)

    def rawlog_case():
        p, c = value(), rng.choice([None, value(), cfg])

        def go():
            for _ in bims.read_rawlog(p, c):
                break

        return "read_rawlog(%s, %s)" % (describe(p), describe(c)), go

    def import_case():
        which = rng.choice(["import_tum", "import_stray", "import_bag"])
        fn = getattr(bims, which)
        if fn is None:
            return "skip", lambda: None
        args = dict(
            out=rng.choice([value(), os.path.join(work, "out.rawlog")]),
            config=rng.choice([None, None, value()]),
            max_frames=rng.choice([1, value()]),
            gz_level=rng.choice([1, value()]),
            progress=rng.choice([None, value(), lambda d, t: None,
                                 lambda: None]),
        )
        first = rng.choice([value(), empty_dir, SAMPLE])
        args["bags" if which == "import_bag" else "folder"] = first
        return "%s(%s)" % (which, describe(args)), lambda: fn(**args)

    makers = [process_case] * 6 + [depth_array_case] * 2 + [
        query_case, config_case, rawlog_case, import_case]
    expected = set(os.listdir(work))
    outcomes = {}
    with open(log_path, "w") as log:
        for i in range(cases):
            what, call = rng.choice(makers)()
            log.write("case %d: %s\n" % (i, what))
            log.flush()
            outcome = "returned"
            try:
                call()
            except HostileError:
                outcome = "HostileError"
            except CLEAN as e:
                outcome = type(e).__name__
                if VERBOSE:
                    print("case %d: %s: %s" % (i, outcome, e), file=sys.stderr)
                msg = str(e)
                for bad in NOT_OURS:
                    if bad in msg:
                        print("case %d: %s\n  %s: %s" % (i, what, type(e).__name__, msg))
                        return 3
            except Exception as e:  # noqa: BLE001 (the finding)
                print("case %d: %s\n  unexpected %s: %s" % (i, what, type(e).__name__, e))
                return 3
            # nothing written under a name made of a bad argument
            made = set(os.listdir(work)) - expected - {"m.ply", "out.rawlog", "out_gt"}
            if made:
                print("case %d: %s\n  wrote %s" % (i, what, sorted(made)))
                return 3
            outcomes[outcome] = outcomes.get(outcome, 0) + 1
        print("outcomes:", ", ".join("%s %d" % kv for kv in sorted(outcomes.items())))
        log.write("done\n")
    return 0


def describe(v, depth=0):
    """A short text of a value (arrays by dtype and shape)."""
    if isinstance(v, dict):
        return ", ".join("%s=%s" % (k, describe(x, depth + 1)) for k, x in v.items())
    shape = getattr(v, "shape", None)
    if shape is not None and hasattr(v, "dtype") and shape != ():
        return "array(%s, %s%s)" % (
            v.dtype, shape, "" if v.flags["C_CONTIGUOUS"] else ", strided")
    text = repr(v)
    return text if len(text) < 60 else text[:57] + "..."


class FuzzPythonApi(unittest.TestCase):
    def test_hostile_arguments_raise_clean_exceptions(self):
        with tempfile.TemporaryDirectory() as d:
            log = os.path.join(d, "cases.log")
            try:
                run = subprocess.run(
                    [sys.executable, os.path.abspath(__file__), "--child",
                     str(SEED), str(CASES), log],
                    capture_output=True, text=True, timeout=600,
                )
                code, out = run.returncode, run.stdout + run.stderr[-2000:]
            except subprocess.TimeoutExpired as e:
                code, out = "timeout (600 s)", str(e.stdout or "")
            last = ""
            if os.path.exists(log):
                with open(log) as f:
                    lines = f.read().splitlines()
                last = lines[-1] if lines else ""
            self.assertEqual(code, 0, "seed %d: %s\nlast case: %s" % (SEED, out, last))
            self.assertEqual(last, "done")


if __name__ == "__main__":
    if len(sys.argv) == 5 and sys.argv[1] == "--child":
        sys.exit(child(int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]))
    unittest.main()
