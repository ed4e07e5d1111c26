"""motiontheater: motion-capture data (ASF/AMC, BVH) read, cut, splice and smoothed.

Skeletons and motions are read and written exactly (:func:`read_asf`,
:func:`read_amc`, :func:`write_asf`, :func:`write_amc`); the numeric work is
done by :mod:`mtcore`, the package's C core, whose smoothing filters are
re-exported here.
"""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("motiontheater")
except PackageNotFoundError:  # running from a source tree that was never installed
    __version__ = "0+unknown"

from mtcore import binomial_filter1d, median_filter1d, pascal_weights, uniform_filter1d
from mtcore.errors import (
    CountError,
    DuplicateError,
    FormatError,
    HierarchyError,
    MissingError,
    NumberError,
    SequenceError,
    TruncatedError,
    UnknownNameError,
)

from .amc import read_amc, skeleton_path_for, write_amc
from .asf import read_asf, write_asf
from .bvh import read_bvh, write_bvh
from .combine import combine
from .convert import to_asf, to_bvh
from .export import write_positions
from .interpolate import Pipeline, interpolate
from .motion import DEFAULT_FRAME_RATE, Motion
from .scene import Scene, Track, read_recipe
from .skeleton import Bone, Root, Skeleton

__all__ = [
    "DEFAULT_FRAME_RATE",
    "Bone",
    "CountError",
    "DuplicateError",
    "FormatError",
    "HierarchyError",
    "MissingError",
    "Motion",
    "NumberError",
    "Pipeline",
    "Root",
    "Scene",
    "SequenceError",
    "Skeleton",
    "Track",
    "TruncatedError",
    "UnknownNameError",
    "__version__",
    "binomial_filter1d",
    "combine",
    "interpolate",
    "median_filter1d",
    "pascal_weights",
    "read_amc",
    "read_asf",
    "read_bvh",
    "read_recipe",
    "skeleton_path_for",
    "to_asf",
    "to_bvh",
    "uniform_filter1d",
    "write_amc",
    "write_asf",
    "write_bvh",
    "write_positions",
]
