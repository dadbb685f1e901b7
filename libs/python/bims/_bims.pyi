"""Type stubs of the C++ module bims._bims (see bims/__init__.py)."""

import os
from typing import Any, Callable, Dict, List, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

class ConfigError(ValueError): ...
class RawlogError(OSError): ...
class UsageError(ValueError): ...

ProgressFn = Callable[[int, int], None]
#: a file path: str or os.PathLike (not empty)
Path = Union[str, "os.PathLike[str]"]

def import_tum(
    folder: Path,
    out: Path,
    config: Optional[Path] = None,
    max_frames: int = 0,
    gz_level: int = 1,
    bonn_gt: bool = False,
    synth_imu: bool = False,
    seed: int = 1,
    progress: Optional[ProgressFn] = None,
) -> Dict[str, Any]: ...
def import_stray(
    folder: Path,
    out: Path,
    config: Optional[Path] = None,
    max_frames: int = 0,
    gz_level: int = 1,
    progress: Optional[ProgressFn] = None,
) -> Dict[str, Any]: ...
def import_bag(
    bags: Union[Path, Sequence[Path]],
    out: Path,
    config: Optional[Path] = None,
    layout: Optional[Path] = None,
    max_frames: int = 0,
    gz_level: int = 1,
    progress: Optional[ProgressFn] = None,
) -> Dict[str, Any]: ...

class Config:
    """An experiment configuration (.ini), read with the programs' checks."""

    def __init__(self) -> None: ...
    @staticmethod
    def from_file(path: Path) -> "Config": ...
    @staticmethod
    def from_string(text: str) -> "Config": ...
    def get(self, section: str, key: str) -> str: ...
    def set(self, section: str, key: str, value: object) -> None: ...
    def effective(self) -> str: ...
    @property
    def source(self) -> str: ...

class Result:
    """What one frame produced."""

    index: int
    stamp: float
    mask: npt.NDArray[np.uint8]
    mask_tier1: npt.NDArray[np.uint8]
    mask_tier2: npt.NDArray[np.uint8]
    mask_flow: npt.NDArray[np.uint8]
    labels: npt.NDArray[np.int8]
    pose: npt.NDArray[np.float64]
    motion: npt.NDArray[np.float64]
    flags: List[str]
    flag_bits: int
    warmup: bool
    flow_off: bool
    times: Dict[str, float]
    moving_voxels: npt.NDArray[np.float64]
    hit_voxels: int

class Voxels:
    """Voxels of a grid with a probability each."""

    centres: npt.NDArray[np.float64]
    probabilities: npt.NDArray[np.float32]
    def __len__(self) -> int: ...

class Pipeline:
    """The segmentation pipeline, one frame at a time. Its calls are
    serialised: it may be shared by threads, one call at a time."""

    def __init__(self, config: Config) -> None: ...
    def process(
        self,
        depth: np.ndarray,
        rgb: Optional[np.ndarray] = None,
        stamp: Optional[float] = None,
        imu: Optional[npt.NDArray[np.float64]] = None,
        K: Optional[np.ndarray] = None,
        depth_units: Optional[float] = None,
    ) -> Result: ...
    @property
    def frames_processed(self) -> int: ...
    @property
    def imu_rejected(self) -> int: ...
    def occupied_voxels(self, p_occupied: float = 0.5) -> Voxels: ...
    def moving_voxels(self) -> Voxels: ...
    def static_voxels(self, p_occupied: Optional[float] = None) -> Voxels: ...
    def save_static_map(self, path: Path, p_occupied: Optional[float] = None) -> int: ...

class _RawlogReader:
    def __init__(self, path: Path, config: Config) -> None: ...
    def __iter__(self) -> "_RawlogReader": ...
    def __next__(self) -> dict: ...
