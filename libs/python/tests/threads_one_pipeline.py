"""One bims.Pipeline used from several Python threads at once (issue 55):
its calls are serialised, so threads hammering one pipeline with frames and
grid queries get whole frames, one at a time. Before, the GIL was released
during a frame with nothing else holding the pipeline: SIGSEGV (6 of 11
runs), SIGABRT, a deadlock, or "decay of frame 1 is still pending".

Each round runs in a child process (python3 threads_one_pipeline.py
--child ROUND), so that a crash or a deadlock fails the test, naming the
round, instead of taking the test runner down."""

import os
import subprocess
import sys
import unittest

SOURCE = os.environ.get("BIMS_SOURCE_DIR", os.getcwd())
SAMPLE = os.path.join(SOURCE, "rawlogs", "pendulum_slow.rawlog")
CONFIG = os.path.join(SOURCE, "config", "default.ini")
ROUNDS = 4
THREADS = 4
FRAMES = 12


def child(round_):
    """THREADS threads each run FRAMES frames through one pipeline, another
    asks for its voxels meanwhile. Stamps come from one counter: a thread
    may get the pipeline after a later stamp was run (a ValueError naming
    the stamp, the one error allowed). Checks what each call got."""
    import threading

    import numpy as np

    import bims

    frames = [f for _, f in zip(range(FRAMES), bims.read_rawlog(SAMPLE))]
    pipe = bims.Pipeline(bims.Config.from_file(CONFIG))
    lock = threading.Lock()
    counter = iter(range(1, 10**9))
    results, errors = [], []
    done = threading.Event()

    def next_stamp():
        with lock:
            return 100.0 + 0.033 * next(counter)

    def worker(k):
        for i, f in enumerate(frames):
            t = next_stamp()
            imu = f.imu.copy()
            imu[:, 0] = t - 0.02 + 0.001 * np.arange(len(imu))
            try:
                r = pipe.process(f.depth, rgb=f.rgb if (i + k) % 3 else None,
                                 stamp=t, imu=imu)
                with lock:
                    results.append(r)
            except ValueError as e:
                if not (str(e).startswith("stamp:") or str(e).startswith("imu:")):
                    errors.append(repr(e))
            except Exception as e:  # noqa: BLE001 (the finding)
                errors.append(repr(e))

    def reader():
        while not done.is_set():
            try:
                pipe.occupied_voxels()
                pipe.static_voxels()
                pipe.moving_voxels()
                pipe.frames_processed
            except Exception as e:  # noqa: BLE001
                errors.append(repr(e))

    threads = [threading.Thread(target=worker, args=(k,)) for k in range(THREADS)]
    query = threading.Thread(target=reader)
    query.start()
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    done.set()
    query.join()
    if errors:
        print("round %d: %s" % (round_, errors[:3]))
        return 3
    # every frame run whole, once: indices 0..n-1, stamps increasing with
    # them, finite poses, masks of the frame's size
    results.sort(key=lambda r: r.index)
    n = len(results)
    ok = (
        n > 0
        and [r.index for r in results] == list(range(n))
        and all(a.stamp < b.stamp for a, b in zip(results, results[1:]))
        and all(np.isfinite(r.pose).all() for r in results)
        and all(r.mask.shape == frames[0].depth.shape for r in results)
        and pipe.frames_processed == n
    )
    if not ok:
        print("round %d: %d frames, indices %s, frames_processed %d" % (
            round_, n, [r.index for r in results][:20], pipe.frames_processed))
        return 3
    print("round %d: %d of %d frames run" % (round_, n, THREADS * FRAMES))
    return 0


class ThreadsOnePipeline(unittest.TestCase):
    def test_several_threads_share_one_pipeline(self):
        for round_ in range(ROUNDS):
            try:
                run = subprocess.run(
                    [sys.executable, os.path.abspath(__file__), "--child", str(round_)],
                    capture_output=True, text=True, timeout=300,
                )
                code, out = run.returncode, run.stdout + run.stderr[-1500:]
            except subprocess.TimeoutExpired:
                code, out = "deadlock (no end after 300 s)", ""
            self.assertEqual(code, 0, "round %d: %s" % (round_, out))

    def test_a_call_from_inside_a_call_is_refused(self):
        """A call made on the same thread while the pipeline runs one (here
        from the stamp's __float__) would wait for itself: a RuntimeError."""
        import bims

        f = next(iter(bims.read_rawlog(SAMPLE)))
        pipe = bims.Pipeline(bims.Config.from_file(CONFIG))

        class Stamp:
            def __float__(self):
                pipe.occupied_voxels()
                return f.stamp

        with self.assertRaises(RuntimeError) as e:
            pipe.process(f.depth, rgb=f.rgb, stamp=Stamp())
        self.assertIn("called again from inside one of its own calls", str(e.exception))
        r = pipe.process(f.depth, rgb=f.rgb, stamp=f.stamp)  # still usable
        self.assertEqual(r.index, 0)


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--child":
        sys.exit(child(int(sys.argv[2])))
    unittest.main()
