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

from ._version import __version__
from .characters.retarget import plan_retarget, retarget
from .characters.rigs import joint_map
from .editing import convert, filtering, interpolators, repair, signal  # noqa: F401 (importing them registers their steps)
from .editing.combine import combine
from .editing.convert import to_asf, to_bvh
from .editing.filtering import filter_motion
from .editing.interpolators import interpolate, median3
from .editing.pipeline import Pipeline
from .editing.scene import Scene, Track, read_recipe
from .feet.contacts import Contacts, Plant, detect_contacts
from .feet.footskate import Cleanup, clean_footskate
from .feet.legs import find_legs
from .feet.skate import skate_metrics
from .formats.amc import read_amc, skeleton_path_for, write_amc
from .formats.asf import read_asf, write_asf
from .formats.bvh import read_bvh, write_bvh
from .formats.gltf_read import read_gltf
from .formats.table import read_take, write_take
from .model import errors
from .model.errors import *  # the exceptions, errors.__all__
from .model.motion import DEFAULT_FRAME_RATE, Motion
from .model.registry import StepError, steps
from .model.skeleton import Bone, Root, Skeleton
from .views import markers  # noqa: F401 (registers the c3d exporter)
from .views.export import export
from .views.gltf import write_gltf
from .views.positions import write_positions

__all__ = [
    "DEFAULT_FRAME_RATE",
    "Bone",
    "Cleanup",
    "Contacts",
    "Motion",
    "Pipeline",
    "Plant",
    "Root",
    "Scene",
    "Skeleton",
    "StepError",
    "Track",
    "__version__",
    "binomial_filter1d",
    "clean_footskate",
    "combine",
    "detect_contacts",
    "export",
    "filter_motion",
    "find_legs",
    "interpolate",
    "joint_map",
    "median3",
    "median_filter1d",
    "pascal_weights",
    "plan_retarget",
    "read_amc",
    "read_asf",
    "read_bvh",
    "read_gltf",
    "read_recipe",
    "read_take",
    "retarget",
    "skate_metrics",
    "skeleton_path_for",
    "steps",
    "to_asf",
    "to_bvh",
    "uniform_filter1d",
    "write_amc",
    "write_asf",
    "write_bvh",
    "write_gltf",
    "write_positions",
    "write_take",
]
__all__ += errors.__all__
