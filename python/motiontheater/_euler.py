"""Euler angles (rotations about fixed axes, applied in order), matrices and
quaternions, vectorised over frames: what the combiner needs to blend
rotations by SLERP and to turn a trajectory about the vertical axis.
Euler angles and matrices convert in C (mtcore.kinematics)."""

from __future__ import annotations

import numpy as np

from mtcore.kinematics import euler_angles as angles  # noqa: F401 (part of this module's vocabulary)
from mtcore.kinematics import euler_matrices as matrices  # noqa: F401
from mtcore.kinematics import rotations_to_quaternions


def quaternions(m: np.ndarray) -> np.ndarray:
    return rotations_to_quaternions(m)


def quaternion_matrices(q: np.ndarray) -> np.ndarray:
    w, x, y, z = np.moveaxis(q / np.linalg.norm(q, axis=-1, keepdims=True), -1, 0)
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
    ], -2)


def slerp(q0: np.ndarray, q1: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Spherical interpolation from q0 to q1 (..., 4) by t (...), along the shorter arc."""
    dot = np.sum(q0 * q1, axis=-1)
    q1 = np.where(dot[..., None] < 0, -q1, q1)
    dot = np.abs(dot)
    theta = np.arccos(np.clip(dot, -1.0, 1.0))
    sin = np.sin(theta)
    near = sin < 1e-9  # (almost) the same rotation: linear is exact enough
    safe = np.where(near, 1.0, sin)
    a = np.where(near, 1 - t, np.sin((1 - t) * theta) / safe)
    b = np.where(near, t, np.sin(t * theta) / safe)
    q = a[..., None] * q0 + b[..., None] * q1
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def nearest_equivalent(angle: np.ndarray, reference: np.ndarray, period: float) -> np.ndarray:
    """angle plus the multiple of period that brings it closest to reference."""
    return angle + period * np.round((reference - angle) / period)
