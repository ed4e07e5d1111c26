"""motiontheater: motion-capture data (ASF/AMC, BVH) read, cut, splice and smoothed.

Skeletons and motions are read and written exactly (:func:`read_asf`,
:func:`read_amc`, :func:`read_bvh` and their writers); every operation on a
motion is a registered step (:func:`steps` lists them), reached as a method
(``motion.median(size=5)``), a :class:`Pipeline` step, a TOML recipe entry, a
command-line verb and a batch step.  The numeric work is done by
:mod:`mtcore`, the package's C core, whose smoothing filters are re-exported
here.
"""

from mtcore import binomial_filter1d, median_filter1d, pascal_weights, uniform_filter1d

from . import convert, errors, export, filtering, interpolators, markers, signal  # noqa: F401 (importing them registers their steps)
from ._version import __version__
from .amc import read_amc, skeleton_path_for, write_amc
from .asf import read_asf, write_asf
from .bvh import read_bvh, write_bvh
from .combine import combine
from .convert import to_asf, to_bvh
from .errors import *  # the exceptions, errors.__all__
from .export import write_positions
from .filtering import filter_motion
from .formats import read_take, write_take
from .interpolators import interpolate, median3
from .motion import DEFAULT_FRAME_RATE, Motion
from .pipeline import Pipeline
from .registry import StepError, steps
from .retarget import plan_retarget, retarget
from .rigs import joint_map
from .scene import Scene, Track, read_recipe
from .skeleton import Bone, Root, Skeleton

__all__ = [
    "DEFAULT_FRAME_RATE",
    "Bone",
    "Motion",
    "Pipeline",
    "Root",
    "Scene",
    "Skeleton",
    "StepError",
    "Track",
    "__version__",
    "binomial_filter1d",
    "combine",
    "filter_motion",
    "interpolate",
    "joint_map",
    "median3",
    "median_filter1d",
    "pascal_weights",
    "plan_retarget",
    "read_amc",
    "read_asf",
    "read_bvh",
    "read_recipe",
    "read_take",
    "retarget",
    "skeleton_path_for",
    "steps",
    "to_asf",
    "to_bvh",
    "uniform_filter1d",
    "write_amc",
    "write_asf",
    "write_bvh",
    "write_positions",
    "write_take",
]
__all__ += errors.__all__
