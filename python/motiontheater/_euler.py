"""Euler angles (rotations about fixed axes, applied in order), matrices and
quaternions, vectorised over frames: what the combiner needs to blend
rotations by SLERP and to turn a trajectory about the vertical axis.
The conversions and SLERP are mtcore's, in C."""

from __future__ import annotations

import numpy as np

from mtcore.kinematics import euler_angles as angles  # noqa: F401 (part of this module's vocabulary)
from mtcore.kinematics import euler_matrices as matrices  # noqa: F401
from mtcore.rotations import matrices_to_quaternions as quaternions  # noqa: F401
from mtcore.rotations import quaternions_to_matrices as quaternion_matrices  # noqa: F401
from mtcore.rotations import slerp  # noqa: F401


def nearest_equivalent(angle: np.ndarray, reference: np.ndarray, period: float) -> np.ndarray:
    """angle plus the multiple of period that brings it closest to reference."""
    return angle + period * np.round((reference - angle) / period)
