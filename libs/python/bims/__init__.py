"""bims: Bayesian independent motion segmentation from RGB-D + IMU.

The pipeline, its configuration and the rawlog reader of the C++ programs
on NumPy arrays (docs/python.md)::

    import bims
    cfg = bims.Config.from_file("config/default.ini")
    pipe = bims.Pipeline(cfg)
    for f in bims.read_rawlog("rawlogs/pendulum_slow.rawlog"):
        r = pipe.process(f.depth, rgb=f.rgb, stamp=f.stamp, imu=f.imu)
        r.mask   # H x W uint8, 255 = moving
        r.pose   # 4 x 4 float64, T_WC
"""

import math
import numbers
from dataclasses import dataclass
from typing import Iterator, Optional

import numpy as np

from ._bims import Config, ConfigError, Pipeline, RawlogError, Result, Voxels
from ._bims import _RawlogReader
from ._bims import UsageError, import_stray, import_tum

try:  # built with the ROS 1 bag libraries (libs/bag)
    from ._bims import import_bag
except ImportError:
    import_bag = None

__all__ = [
    "Config",
    "ConfigError",
    "DepthArray",
    "Frame",
    "Pipeline",
    "RawlogError",
    "Result",
    "UsageError",
    "Voxels",
    "import_stray",
    "import_tum",
    "read_rawlog",
]
if import_bag is not None:
    __all__.append("import_bag")


class DepthArray(np.ndarray):
    """A depth image (H x W) that carries its camera matrix ``K`` (3 x 3)
    and its ``units`` (metres per reading of a uint16 image), so that
    ``Pipeline.process`` needs neither argument. ``range_is_depth`` False:
    the readings are Euclidean ranges along each pixel's ray (MRPT's
    ``range_is_depth``), not depth along the optical axis. A slice keeps
    them: crop with care."""

    def __new__(cls, array, K=None, units=None, range_is_depth=True):
        obj = np.asarray(array).view(cls)
        if K is not None:
            try:
                K = np.asarray(K, dtype=np.float64)
            except (TypeError, ValueError):
                raise TypeError(
                    "K: a 3 x 3 camera matrix of numbers expected, got "
                    + type(K).__name__
                ) from None
        obj.K = K
        obj.units = _checked_units(units, obj.dtype)
        obj.range_is_depth = bool(range_is_depth)
        return obj

    def __array_finalize__(self, obj):
        self.K = getattr(obj, "K", None)
        # units are those of integer readings: an array converted to float
        # (metres, e.g. by astype) does not keep them
        units = getattr(obj, "units", None)
        self.units = units if self.dtype.kind in "ui" else None
        self.range_is_depth = getattr(obj, "range_is_depth", True)


def _checked_units(units, dtype):
    """``units`` of a DepthArray of ``dtype``: None, or a finite number > 0
    (metres per reading); float depth is in metres (units 1 or None)."""
    if units is None:
        return None
    if isinstance(units, (bool, np.bool_)) or not isinstance(
        units, (numbers.Real, np.number)
    ):
        raise TypeError(
            "units: metres per reading (a number, e.g. 0.001) expected, got "
            + type(units).__name__
            + (f" {units!r}" if isinstance(units, (str, bytes)) else "")
        )
    u = float(units)
    if not (math.isfinite(u) and u > 0):
        raise ValueError(f"units: {u} is not a finite value > 0 [m]")
    if dtype.kind == "f" and u != 1:
        raise ValueError(
            f"units: {u} for float depth, which is in metres: units apply to "
            "uint16 readings (leave it None)"
        )
    return units


@dataclass
class Frame:
    """One RGB-D frame of a recording, with the IMU samples since the
    previous one."""

    index: int  #: 3D-scan index in the input, from 0
    stamp: float  #: camera time [s]
    depth: DepthArray  #: H x W uint16 readings (x depth.units [m]; ranges if not depth.range_is_depth)
    rgb: Optional[np.ndarray]  #: H x W x 3 uint8 RGB, or None (depth only)
    imu: np.ndarray  #: N x 14 float64: t, gyro, accel, mag, quaternion wxyz (NaN: absent)
    K: np.ndarray  #: 3 x 3 camera matrix [px]


def read_rawlog(path: str, config: Optional[Config] = None) -> Iterator[Frame]:
    """The frames of an MRPT rawlog, in the order bims-run runs them: the
    config's [sensors] labels, its IMU checks and depth correction (the
    built-in defaults without one). The file is opened here (a missing,
    empty or unreadable one raises now); a rawlog without a 3D scan raises
    ``RawlogError`` when it is read, as bims-run does."""
    reader = _RawlogReader(path, config if config is not None else Config())
    return _frames(reader)


def _frames(reader) -> Iterator[Frame]:
    for d in reader:
        depth = DepthArray(
            d["depth"],
            K=d["K"],
            units=d["depth_units"],
            range_is_depth=d["range_is_depth"],
        )
        yield Frame(
            index=d["index"],
            stamp=d["stamp"],
            depth=depth,
            rgb=d["rgb"],
            imu=d["imu"],
            K=d["K"],
        )
