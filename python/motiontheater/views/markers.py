"""Virtual markers to C3D: every joint and end site of a motion as a marker (the ``c3d`` extra,
through the maintained pure-Python ``c3d`` package).  CSV, NPZ and TRC are in
:mod:`motiontheater.views.positions`.

The C3D file says what it holds: POINT:RATE is the motion's frame rate,
POINT:UNITS "mm", POINT:LABELS the skeleton's point names (root under its
own name, then the bones; BVH end sites as ``<joint>_End``), TRIAL's start
frame the motion's first frame, and POINT:X_SCREEN / Y_SCREEN "+X" / "+Y":
the axes are the take's own, Y up, not turned to C3D's customary Z up.
A missing sample (a NaN position, from NaN channels) is written as C3D
marks one: residual -1, coordinates 0.

Coordinates are float32 millimetres, C3D's only floating point format: they
round to within half a float32 step, 6.1e-5 mm below 1.024 m from the
origin, 1.2e-4 mm below 2.048 m, 2.4e-4 mm below 4.096 m.
"""

from __future__ import annotations

import warnings
from typing import Annotated

import numpy as np

from .._io import Source, output
from .._optional import require
from ..model.motion import Motion
from ..model.registry import exporter

MAX_MARKERS = 255  # one POINT:LABELS parameter; more needs LABELS2, which readers handle unevenly


def c3d_points(motion: Motion, *, workers: int | None = None) -> np.ndarray:
    """The C3D point samples (frames, points, 5) that :func:`write_c3d` writes: x, y, z in
    millimetres, residual (0, or -1 for a missing sample, whose coordinates are 0) and the
    camera mask (0)."""
    positions = motion.positions(meters=True, workers=workers) * 1000.0
    missing = np.logical_not(np.isfinite(positions).all(axis=2))
    points = np.zeros(positions.shape[:2] + (5,))
    points[..., :3] = np.where(missing[..., None], 0.0, positions)
    points[..., 3] = np.where(missing, -1.0, 0.0)
    return points


@exporter("c3d", (".c3d",), "write every joint and end site as a C3D marker (millimetres; the c3d extra)")
def write_c3d(
    motion: Motion,
    target: Source,
    *,
    workers: Annotated[int | None, "threads (default: every core for large takes)"] = None,
) -> None:
    """Write every joint and end site of the motion as a C3D marker (see the module docstring).
    A path is written atomically; ValueError for a motion without frames or with more than
    255 points."""
    c3d = require("c3d", "c3d", "writing C3D files")
    names = motion.skeleton.point_names
    if motion.frames == 0:
        raise ValueError("a C3D file needs at least one frame, and the motion has none")
    if len(names) > MAX_MARKERS:
        raise ValueError(f"C3D takes at most {MAX_MARKERS} markers here, and the skeleton has {len(names)} points")
    points = c3d_points(motion, workers=workers)
    writer = c3d.Writer(point_rate=float(motion.frame_rate), point_units="mm  ")
    writer.set_point_labels(list(names))
    writer.set_screen_axis("+X", "+Y")
    writer.set_start_frame(max(1, motion.first_frame))
    no_analog = np.zeros((0, 0))
    writer.add_frames([(frame, no_analog) for frame in points])
    with output(target) as f, warnings.catch_warnings():
        warnings.filterwarnings("ignore", "No analog data", UserWarning)  # markers only, on purpose
        writer.write(f)
