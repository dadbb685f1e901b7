"""The Python module against the programs: the same masks and poses as
bims-run on the bundled sample, the same strict config reader, and clear
exceptions naming the argument for bad input."""

import os
import subprocess
import tempfile
import unittest
import warnings

import numpy as np

import bims

SOURCE = os.environ.get("BIMS_SOURCE_DIR", os.getcwd())
BIN = os.environ.get("BIMS_BIN_DIR", os.path.join(SOURCE, "build", "bin"))
SAMPLE = os.path.join(SOURCE, "rawlogs", "pendulum_slow.rawlog")
SHARED = os.environ.get(
    "BIMS_SHARED_DATA_DIR", os.path.join(SOURCE, "..", "shared", "data")
)
CONFIG = os.path.join(SOURCE, "config", "default.ini")


def read_png(path):
    import cv2  # python3-opencv

    img = cv2.imread(path, cv2.IMREAD_UNCHANGED)
    if img is None:
        raise FileNotFoundError(path)
    return img


def quat_to_matrix(qx, qy, qz, qw):
    x, y, z, w = qx, qy, qz, qw
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


class Package(unittest.TestCase):
    def test_the_package_is_the_one_under_test(self):
        want = os.environ.get("BIMS_EXPECT_PACKAGE_DIR")
        if want is None:  # the build tree's: PYTHONPATH says which
            want = os.path.join(os.environ["PYTHONPATH"].split(os.pathsep)[0], "bims")
        self.assertEqual(
            os.path.realpath(os.path.dirname(bims.__file__)), os.path.realpath(want)
        )
        self.assertTrue(bims._bims.__file__.startswith(os.path.dirname(bims.__file__)))


class SameAsBimsRun(unittest.TestCase):
    def test_masks_and_poses_of_the_sample_equal_bims_runs(self):
        self.assertTrue(os.path.exists(SAMPLE), SAMPLE)
        with tempfile.TemporaryDirectory() as out:
            run = subprocess.run(
                [os.path.join(BIN, "bims-run"), CONFIG, SAMPLE, "-o", out, "-q"],
                capture_output=True,
                text=True,
            )
            self.assertEqual(run.returncode, 0, run.stderr)
            traj = {}
            with open(os.path.join(out, "trajectory.txt")) as f:
                for line in f:
                    if line.startswith("#"):
                        continue
                    v = [float(x) for x in line.split()]
                    traj[len(traj)] = v
            pipe = bims.Pipeline(bims.Config.from_file(CONFIG))
            n = 0
            moving = 0
            for f in bims.read_rawlog(SAMPLE):
                r = pipe.process(f.depth, rgb=f.rgb, stamp=f.stamp, imu=f.imu)
                self.assertEqual(r.index, n)
                self.assertEqual(r.mask.dtype, np.uint8)
                self.assertEqual(r.mask.shape, f.depth.shape)
                want = read_png(os.path.join(out, "masks", f"{n:06d}.png"))
                self.assertTrue(
                    np.array_equal(r.mask, want), f"mask of frame {n} differs"
                )
                moving += int(np.count_nonzero(r.mask))
                t, tx, ty, tz, qx, qy, qz, qw = traj[n]
                self.assertAlmostEqual(r.stamp, t, places=5)
                self.assertEqual(r.pose.shape, (4, 4))
                np.testing.assert_allclose(
                    r.pose[:3, 3], [tx, ty, tz], atol=2e-9, err_msg=f"frame {n}"
                )
                np.testing.assert_allclose(
                    r.pose[:3, :3],
                    quat_to_matrix(qx, qy, qz, qw),
                    atol=2e-8,
                    err_msg=f"frame {n}",
                )
                self.assertIsInstance(r.flags, list)
                n += 1
            self.assertEqual(n, 150)
            self.assertEqual(pipe.frames_processed, 150)
            self.assertGreater(moving, 0, "the pendulum is never found")
            self.check_grids_equal_bims_runs(pipe, r, out)

    def check_grids_equal_bims_runs(self, pipe, last, out):
        """The grids after the run: the last frame's moving voxels and the
        static map (.ply and .bt) as bims-run wrote them, byte for byte."""
        moving = pipe.moving_voxels()
        self.assertGreater(len(moving), 0)
        self.assertEqual(moving.centres.shape, (len(moving), 3))
        self.assertEqual(moving.probabilities.dtype, np.float32)
        self.assertTrue(np.all(moving.probabilities > 0.5))
        np.testing.assert_array_equal(moving.centres, last.moving_voxels)
        with open(os.path.join(out, "moving_voxels", "000149.ply")) as f:
            lines = f.read().split("end_header\n", 1)[1].split()
        written = np.array(lines, dtype=np.float64).reshape(-1, 3)
        np.testing.assert_allclose(written, moving.centres, atol=6e-5)  # %.4f

        static = pipe.static_voxels()
        occupied = pipe.occupied_voxels()
        self.assertGreater(len(static), 0)
        self.assertGreaterEqual(len(occupied), len(static))
        self.assertTrue(np.all(static.probabilities > 0.7))  # static_p_occupied
        self.assertTrue(np.all(occupied.probabilities > 0.5))
        self.assertLess(len(pipe.occupied_voxels(0.9)), len(occupied))
        with tempfile.TemporaryDirectory() as mine:
            for name in ("static_map.ply", "static_map.bt"):
                n = pipe.save_static_map(os.path.join(mine, name))
                self.assertGreater(n, 0)
                with open(os.path.join(mine, name), "rb") as a, open(
                    os.path.join(out, name), "rb"
                ) as b:
                    self.assertEqual(a.read(), b.read(), name)
            self.assertEqual(
                pipe.save_static_map(os.path.join(mine, "s.ply")), len(static)
            )


class Config(unittest.TestCase):
    def test_a_missing_file_is_file_not_found_naming_it(self):
        with self.assertRaises(FileNotFoundError) as e:
            bims.Config.from_file("no/such/dir/x.ini")
        self.assertIn("no/such/dir/x.ini", str(e.exception))

    def test_unknown_keys_and_bad_values_are_value_errors_naming_them(self):
        with open(CONFIG) as f:
            text = f.read()
        self.assertIn("[grids]", text)
        with self.assertRaises(ValueError) as e:
            bims.Config.from_string(text.replace("[grids]", "[grids]\nvoxel_sise = 0.05", 1))
        self.assertIn("voxel_sise", str(e.exception))
        with self.assertRaises(ValueError) as e:
            bims.Config.from_string(text + "\n[no_such_section]\nx = 1\n")
        self.assertIn("no_such_section", str(e.exception))
        cfg = bims.Config.from_file(CONFIG)
        with self.assertRaises(ValueError) as e:
            cfg.set("grids", "voxel_size", -1)
        self.assertIn("voxel_size", str(e.exception))
        with self.assertRaises(KeyError):
            cfg.get("grids", "no_such_key")

    def test_get_set_and_effective(self):
        cfg = bims.Config.from_file(CONFIG)
        cfg.set("grids", "voxel_size", 0.08)
        self.assertAlmostEqual(float(cfg.get("grids", "voxel_size")), 0.08)
        again = bims.Config.from_string(cfg.effective())
        self.assertEqual(again.get("grids", "voxel_size"), cfg.get("grids", "voxel_size"))
        cfg.set("pipeline", "flow_thread", False)
        self.assertEqual(cfg.get("pipeline", "flow_thread"), "false")


class EuclideanRanges(unittest.TestCase):
    """A DepthArray of ranges along each pixel's ray (range_is_depth False,
    as read_rawlog gives such a rawlog's scans) runs as the same depth."""

    def run_frames(self, frames, to_array):
        pipe = bims.Pipeline(bims.Config.from_file(CONFIG))
        out = []
        for f in frames:
            r = pipe.process(to_array(f), rgb=f.rgb, stamp=f.stamp, imu=f.imu)
            out.append((r.pose.copy(), r.mask.copy()))
        return out

    def test_ranges_run_as_their_depth(self):
        frames = [f for _, f in zip(range(40), bims.read_rawlog(SAMPLE))]
        K = frames[0].K
        H, W = frames[0].depth.shape
        u, v = np.meshgrid(np.arange(W), np.arange(H))
        ray = np.sqrt(
            1 + ((u - K[0, 2]) / K[0, 0]) ** 2 + ((v - K[1, 2]) / K[1, 1]) ** 2
        ).astype(np.float32)

        def metres(f):
            return f.depth.astype(np.float32) * np.float32(f.depth.units)

        depth = self.run_frames(frames, lambda f: bims.DepthArray(metres(f), K=K))
        ranges = self.run_frames(
            frames,
            lambda f: bims.DepthArray(metres(f) * ray, K=K, range_is_depth=False),
        )
        wrong = self.run_frames(  # the ranges taken for depth
            frames, lambda f: bims.DepthArray(metres(f) * ray, K=K)
        )

        def worst(a, b):
            dt = max(np.abs(x[0][:3, 3] - y[0][:3, 3]).max() for x, y in zip(a, b))
            px = sum(int(np.count_nonzero(x[1] != y[1])) for x, y in zip(a, b))
            return dt, px

        dt, px = worst(depth, ranges)
        self.assertLess(dt, 0.002)
        self.assertLess(px, 0.002 * H * W * len(frames))
        dt_wrong, px_wrong = worst(depth, wrong)
        self.assertGreater(px_wrong, 5 * max(px, 1))
        self.assertGreater(dt_wrong, 5 * dt)


class Importers(unittest.TestCase):
    """bims.import_tum / import_stray: the programs' imports, byte for
    byte, with their report and their errors."""

    def same_as_program(self, program, args, imported):
        """Runs PROGRAM ARGS -o A.rawlog and imported(B.rawlog); the rawlogs
        and the side files are the same bytes, the report is the program's
        stdout."""
        with tempfile.TemporaryDirectory() as d:
            a, b = os.path.join(d, "a.rawlog"), os.path.join(d, "b.rawlog")
            run = subprocess.run(
                [os.path.join(BIN, program)] + args + ["-o", a, "-q"],
                capture_output=True,
                text=True,
            )
            self.assertEqual(run.returncode, 0, run.stderr)
            seen = []
            summary = imported(b, lambda done, total: seen.append((done, total)))
            self.assertEqual(
                summary["report"],
                run.stdout.replace(os.path.join(d, "a"), os.path.join(d, "b")),
            )
            self.assertGreater(len(seen), 1)
            self.assertEqual([x[0] for x in seen], sorted(x[0] for x in seen))
            for name in sorted(os.listdir(d)):
                if name.startswith("a"):
                    self.compare(os.path.join(d, name), os.path.join(d, "b" + name[1:]))
            frames = list(bims.read_rawlog(b))
            self.assertEqual(len(frames), summary["frames"])
            return summary

    def recording(self, name):
        """A shared real recording (never in the repository): skipped when
        this checkout has none, as the C++ tests do (bims_test/data.h)."""
        folder = os.path.join(SHARED, name)
        if not os.path.isdir(folder):
            self.skipTest(f"{folder}: no such shared recording")
        return folder

    def compare(self, x, y):
        if os.path.isdir(x):
            self.assertEqual(sorted(os.listdir(x)), sorted(os.listdir(y)))
            for n in os.listdir(x):
                self.compare(os.path.join(x, n), os.path.join(y, n))
            return
        with open(x, "rb") as f, open(y, "rb") as g:
            self.assertEqual(f.read(), g.read(), os.path.basename(x))

    def test_import_tum_is_bims_import_tum(self):
        folder = self.recording("bonn_crowd_f150_349")
        config = os.path.join(SOURCE, "config", "bonn.ini")
        s = self.same_as_program(
            "bims-import-tum",
            [folder, "--config", config, "--bonn-gt", "--max-frames", "4"],
            lambda out, progress: bims.import_tum(
                folder, out, config=config, bonn_gt=True, max_frames=4,
                progress=progress,
            ),
        )
        self.assertEqual(s["frames"], 4)
        self.assertEqual(s["gt_poses"], 4)

    def test_import_stray_is_bims_import_stray(self):
        folder = self.recording("stray_early")
        config = os.path.join(SOURCE, "config", "stray.ini")
        s = self.same_as_program(
            "bims-import-stray",
            [folder, "--config", config, "--max-frames", "5"],
            lambda out, progress: bims.import_stray(
                folder, out, config=config, max_frames=5, progress=progress
            ),
        )
        self.assertEqual(s["frames"], 5)
        self.assertGreater(s["imu"], 0)

    def test_the_programs_errors(self):
        folder = self.recording("stray_early")
        with tempfile.TemporaryDirectory() as d:
            with self.assertRaises(ValueError) as e:
                bims.import_stray(folder, os.path.join(d, "x.rawlog"), gz_level=12)
            self.assertEqual(str(e.exception), "--gz must be in 0..9")
            with self.assertRaises(ValueError):  # an output may not be an input
                bims.import_stray(folder, os.path.join(folder, "imu.csv"))
            with self.assertRaises(RuntimeError) as e:
                bims.import_tum(os.path.join(d, "none"), os.path.join(d, "x.rawlog"))
            self.assertIn("none", str(e.exception))
            with self.assertRaises(TypeError):
                bims.import_tum(folder, os.path.join(d, "x.rawlog"), progress=3)

            def stop(done, total):  # the user stops it from the callback
                if done >= 2:
                    raise KeyError("stop here")

            with self.assertRaises(KeyError):
                bims.import_stray(
                    folder, os.path.join(d, "x.rawlog"), max_frames=5, progress=stop
                )
            self.assertEqual(os.listdir(d), [])  # no partial output


class BadInput(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        frames = bims.read_rawlog(SAMPLE)
        cls.f = next(frames)

    def pipe(self):
        return bims.Pipeline(bims.Config.from_file(CONFIG))

    def expect(self, error, arg, **kwargs):
        f = self.f
        args = dict(depth=f.depth, rgb=f.rgb, stamp=f.stamp, imu=f.imu)
        args.update(kwargs)
        p = self.pipe()
        with self.assertRaises(error) as e:
            p.process(**args)
        self.assertTrue(str(e.exception).startswith(arg + ":"), str(e.exception))
        self.assertEqual(p.frames_processed, 0)

    def test_each_bad_argument_is_named(self):
        f = self.f
        self.expect(TypeError, "depth", depth=np.asarray(f.depth, dtype=np.int32))
        self.expect(ValueError, "depth", depth=bims.DepthArray(f.depth[0], K=f.K))
        self.expect(
            ValueError, "depth", depth=bims.DepthArray(f.depth[:, ::2], K=f.K)
        )
        nan = bims.DepthArray(f.depth.astype(np.float32) * 0.001, K=f.K)
        nan[3, 4] = np.nan
        self.expect(ValueError, "depth", depth=nan)
        self.expect(ValueError, "rgb", rgb=f.rgb[:-2])
        self.expect(TypeError, "rgb", rgb=f.rgb.astype(np.float32))
        self.expect(ValueError, "rgb", rgb=f.rgb[:, ::2])
        self.expect(ValueError, "K", depth=np.asarray(f.depth))
        self.expect(ValueError, "stamp", stamp=None)
        out_of_order = np.zeros((2, 7))
        out_of_order[:, 0] = [f.stamp - 0.01, f.stamp - 0.02]
        out_of_order[:, 6] = 9.81
        self.expect(ValueError, "imu", imu=out_of_order)
        self.expect(ValueError, "imu", imu=np.zeros((3, 5)))

    def test_bad_grid_queries_are_named(self):
        p = self.pipe()
        f = self.f
        p.process(f.depth, rgb=f.rgb, stamp=f.stamp)
        with self.assertRaises(ValueError) as e:
            p.occupied_voxels(1.5)
        self.assertTrue(str(e.exception).startswith("p_occupied:"))
        with tempfile.TemporaryDirectory() as d:
            with self.assertRaises(ValueError) as e:
                p.save_static_map(os.path.join(d, "map.txt"))
            self.assertTrue(str(e.exception).startswith("path:"))
            with self.assertRaises(RuntimeError) as e:
                p.save_static_map(os.path.join(d, "no", "such", "map.ply"))
            self.assertIn("map.ply", str(e.exception))

    def test_stamps_must_increase(self):
        f = self.f
        p = self.pipe()
        p.process(f.depth, rgb=f.rgb, stamp=f.stamp)
        with self.assertRaises(ValueError) as e:
            p.process(f.depth, rgb=f.rgb, stamp=f.stamp)
        self.assertTrue(str(e.exception).startswith("stamp:"))

    def test_float_metres_and_depth_only_frames_run(self):
        f = self.f
        p = self.pipe()
        metres = (f.depth.astype(np.float32) * np.float32(f.depth.units)).copy()
        r = p.process(metres, stamp=f.stamp, K=f.K)
        self.assertEqual(r.mask.shape, f.depth.shape)
        self.assertTrue(r.flow_off)


class Issue55(unittest.TestCase):
    """Hostile input, third round: each refusal or repair of issue 55's
    campaign on the Python module."""

    @classmethod
    def setUpClass(cls):
        cls.frames = [f for _, f in zip(range(12), bims.read_rawlog(SAMPLE))]
        cls.f = cls.frames[0]

    def pipe(self, **sets):
        cfg = bims.Config.from_file(CONFIG)
        for key, v in sets.items():
            section, name = key.split("__")
            cfg.set(section, name, v)
        return bims.Pipeline(cfg)

    def raises(self, error, start, call):
        with self.assertRaises(error) as e:
            call()
        self.assertTrue(str(e.exception).startswith(start), str(e.exception))
        return str(e.exception)

    def test_arrays_beyond_the_input_image_limits_are_refused(self):
        """[input] image_max_side / image_max_pixels apply to arrays as to
        files: before, 16384 x 16384 took 4.9 GB, then MemoryError."""
        f = self.f
        p = self.pipe(input__image_max_side=300)  # the config's limits
        self.raises(ValueError, "depth: 320 x 240 pixels, beyond the 300 per side",
                    lambda: p.process(f.depth, rgb=f.rgb, stamp=f.stamp))
        p = self.pipe(input__image_max_pixels=320 * 240 - 1)
        self.raises(ValueError, "depth: 320 x 240 pixels",
                    lambda: p.process(f.depth.astype(np.float32) * np.float32(0.001),
                                      stamp=f.stamp, K=f.K))
        self.assertEqual(p.frames_processed, 0)
        self.raises(  # the defaults (zeros: their pages are never touched)
            ValueError, "depth: 16384 x 16384 pixels, beyond the 16384 per side "
            "and 67108864 pixels bims reads ([input] image_max_side, "
            "image_max_pixels)",
            lambda: self.pipe().process(
                np.zeros((16384, 16384), np.uint16), stamp=f.stamp, K=f.K),
        )

    def run_frames(self, imu_of):
        """Poses, masks and flags of the first frames, each with the IMU
        rows imu_of(i, f) gives."""
        p = self.pipe()
        out = []
        for i, f in enumerate(self.frames):
            r = p.process(f.depth, rgb=f.rgb, stamp=f.stamp, imu=imu_of(i, f))
            out.append((r.pose.copy(), r.mask.copy(), r.flags))
        return p, out

    def test_imu_rows_no_imu_gives_are_dropped_counted_and_warned(self):
        """One IMU row with gyro inf or 1e300 turned every later pose NaN
        and every mask empty, without a word; now it is not used, as the
        rawlog readers do (bims::imuSampleProblem), with a RuntimeWarning,
        the frame flagged imu_rejected and Pipeline.imu_rejected counting."""

        def bad(i, f):
            imu = f.imu
            if i in (3, 7) and len(imu):
                row = imu[:1].copy()
                row[0, 1] = np.inf if i == 3 else 1e300  # gyro x
                imu = np.vstack([row, imu])
            return imu

        _, clean = self.run_frames(lambda i, f: f.imu)
        with warnings.catch_warnings(record=True) as seen:
            warnings.simplefilter("always")
            p, dirty = self.run_frames(bad)
        said = [str(w.message) for w in seen if w.category is RuntimeWarning]
        self.assertEqual(len(said), 2, said)
        self.assertTrue(said[0].startswith("imu: 1 sample(s) not used"), said[0])
        self.assertIn("IMU_WX = inf (not finite)", said[0])
        self.assertIn("IMU_WX = 1e+300 (beyond +-100 rad/s)", said[1])
        self.assertEqual(p.imu_rejected, 2)
        for i, ((pc, mc, fc), (pd, md, fd)) in enumerate(zip(clean, dirty)):
            self.assertTrue(np.isfinite(pd).all(), f"frame {i}")
            np.testing.assert_array_equal(pc, pd, err_msg=f"frame {i}")
            np.testing.assert_array_equal(mc, md, err_msg=f"frame {i}")
            self.assertEqual("imu_rejected" in fd, i in (3, 7), f"frame {i}: {fd}")
            self.assertEqual([x for x in fd if x != "imu_rejected"], fc)
        with warnings.catch_warnings():  # warnings as errors: nothing used
            warnings.simplefilter("error")
            p = self.pipe()
            f = self.f
            with self.assertRaises(RuntimeWarning):
                p.process(f.depth, rgb=f.rgb, stamp=f.stamp, imu=bad(3, f))
            self.assertEqual(p.frames_processed, 0)

    def test_float_depth_beyond_the_farthest_range_is_no_reading(self):
        """One float32 pixel at 1e6 m made the 16-bit scale follow it: every
        other reading became 0 and the frame's cloud was empty. A reading
        farther than any stage reads is no reading, as a depth file's."""
        f = self.f
        metres = np.ascontiguousarray(f.depth.astype(np.float32) * np.float32(0.001))
        far = metres.copy()
        far[5, 5] = 1e6
        far[100, 7] = 9.5  # beyond [grids] max_range 8 and every stage's
        near = metres.copy()
        near[5, 5] = near[100, 7] = 0
        a = self.pipe().process(far, rgb=f.rgb, stamp=f.stamp, K=f.K)
        b = self.pipe().process(near, rgb=f.rgb, stamp=f.stamp, K=f.K)
        self.assertGreater(b.hit_voxels, 1000)
        self.assertEqual(a.hit_voxels, b.hit_voxels)
        np.testing.assert_array_equal(a.mask, b.mask)
        np.testing.assert_array_equal(a.pose, b.pose)

    def test_importers_check_their_arguments(self):
        """bims.import_stray(folder, None) wrote files named None: paths are
        str or os.PathLike, not empty, as the programs take them."""
        import pathlib

        with tempfile.TemporaryDirectory() as d:
            cwd = os.getcwd()
            os.chdir(d)
            try:
                self.raises(TypeError, "out: a path (str or os.PathLike) expected, "
                            "got NoneType", lambda: bims.import_stray(d, None))
                self.raises(TypeError, "folder: a path", lambda: bims.import_stray(None, "x.rawlog"))
                self.raises(ValueError, "out: an empty path", lambda: bims.import_tum(d, ""))
                self.raises(TypeError, "config: a path",
                            lambda: bims.import_tum(d, "x.rawlog", config=3))
                if bims.import_bag is not None:
                    self.raises(TypeError, "bags: a path", lambda: bims.import_bag([d, 5], "x.rawlog"))
                    self.raises(ValueError, "bags: no bag given", lambda: bims.import_bag([], "x.rawlog"))
                    self.raises(TypeError, "layout: a path",
                                lambda: bims.import_bag(d, "x.rawlog", layout=1.5))
                # a pathlib.Path is a path (here: not a capture)
                self.raises(RuntimeError, d, lambda: bims.import_stray(pathlib.Path(d), pathlib.Path(d) / "o.rawlog"))
                self.assertEqual(os.listdir(d), [])
            finally:
                os.chdir(cwd)
        self.raises(TypeError, "path: a path", lambda: bims.Config.from_file(None))
        self.raises(TypeError, "path: a path", lambda: bims.read_rawlog(7))
        self.raises(TypeError, "path: a path", lambda: bims.Pipeline(bims.Config()).save_static_map(None))

    def test_unclear_messages_made_clear(self):
        f = self.f
        # DepthArray(units='0.001') was pybind11's "Unable to cast"
        self.raises(TypeError, "units: metres per reading (a number, e.g. 0.001) "
                    "expected, got str '0.001'",
                    lambda: bims.DepthArray(f.depth, K=f.K, units="0.001"))
        d = bims.DepthArray(f.depth, K=f.K)
        d.units = "0.001"  # set afterwards
        self.raises(TypeError, "depth.units: metres per reading",
                    lambda: self.pipe().process(d, stamp=f.stamp))
        self.raises(TypeError, "depth_units: metres per reading",
                    lambda: self.pipe().process(f.depth, stamp=f.stamp, depth_units="1"))
        self.raises(TypeError, "stamp: a time [s] (a number) expected, got str",
                    lambda: self.pipe().process(f.depth, stamp="1.5"))
        self.raises(TypeError, "p_occupied: a probability in [0, 1) expected",
                    lambda: self.pipe().occupied_voxels("0.5"))
        self.raises(ValueError, "stamp: -1 s is outside the times MRPT's clock holds",
                    lambda: self.pipe().process(f.depth, stamp=-1.0))
        # depth_units with float depth (metres) contradicts it: refused
        metres = f.depth.astype(np.float32) * np.float32(0.001)
        self.assertIsNone(metres.units)  # (astype to float drops them)
        self.raises(ValueError, "depth_units: 0.001 for float32 depth, which is in "
                    "metres", lambda: self.pipe().process(metres, stamp=f.stamp, depth_units=0.001))
        self.raises(ValueError, "units: 0.001 for float depth",
                    lambda: bims.DepthArray(metres, K=f.K, units=0.001))
        self.pipe().process(metres, stamp=f.stamp, depth_units=1)  # agrees
        # an empty file is not a rawlog; a rawlog without a 3D scan of the
        # label raises as bims-run does
        with tempfile.TemporaryDirectory() as tmp:
            empty = os.path.join(tmp, "e.rawlog")
            open(empty, "w").close()
            msg = self.raises(bims.RawlogError, empty, lambda: bims.read_rawlog(empty))
            self.assertIn("an empty file (0 bytes), not a rawlog", msg)
        other = bims.Config.from_file(CONFIG)
        other.set("sensors", "rgbd_label", "OTHER")
        self.raises(bims.RawlogError, SAMPLE + ": no CObservation3DRangeScan (RGB-D) "
                    "observation with label 'OTHER'", lambda: list(bims.read_rawlog(SAMPLE, other)))

    def test_images_too_small_for_the_pipeline_are_refused(self):
        """A 1 x 1 depth hit OpenCV's !ssize.empty() assertion; 40 x 8 with
        an image crashed in OpenCV's DIS. The smallest sizes the keyframe
        alignment's pyramid and the observed flow take, named."""
        f = self.f
        K = np.array([[30.0, 0, 2], [0, 30.0, 2], [0, 0, 1]])
        one = np.full((1, 1), 1000, np.uint16)
        self.raises(ValueError, "depth: 1x1 is too small for the keyframe alignment, "
                    "whose pyramid halves it [anchor] coarsest_level = 2 times: it "
                    "needs at least 4 pixels per side",
                    lambda: self.pipe().process(one, stamp=1.0, K=K))
        p = self.pipe(anchor__enable=False)  # then depth only runs at any size
        p.process(one, stamp=1.0, K=K)
        p.process(one, stamp=1.1, K=K)
        wide = np.full((8, 40), 1000, np.uint16)
        rgb = np.zeros((8, 40, 3), np.uint8)
        self.raises(ValueError, "depth: 40x8 is too small for the observed flow "
                    "(OpenCV's DIS, preset fast): it needs at least 32 pixels on the "
                    "shorter side and 91 on the longer one",
                    lambda: self.pipe().process(wide, rgb=rgb, stamp=1.0, K=K))
        self.pipe().process(wide, stamp=1.0, K=K)  # depth only: no flow
        p = self.pipe(flow__method="farneback")
        for k in range(3):
            p.process(wide, rgb=rgb, stamp=1.0 + k, K=K)
        # one pipeline takes one image size (the tracker's, the grids'
        # images): another is named, not an assertion inside a stage
        p = self.pipe()
        p.process(f.depth, rgb=f.rgb, stamp=f.stamp)
        self.raises(ValueError, "depth: 80x60 differs from the previous frames' 320x240",
                    lambda: p.process(np.ascontiguousarray(f.depth[:60, :80]), stamp=f.stamp + 1, K=f.K))
        p.process(f.depth, rgb=f.rgb, stamp=f.stamp + 2)
        self.assertEqual(p.frames_processed, 2)


if __name__ == "__main__":
    unittest.main()
