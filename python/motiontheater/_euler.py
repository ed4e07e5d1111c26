"""Euler angles (rotations about fixed axes, applied in order), matrices and
quaternions, vectorised over frames: what the combiner needs to blend
rotations by SLERP and to turn a trajectory about the vertical axis."""

from __future__ import annotations

import numpy as np

from mtcore.kinematics import rotations_to_quaternions


def _axis_matrices(axis: str, angles: np.ndarray) -> np.ndarray:
    c, s = np.cos(angles), np.sin(angles)
    m = np.zeros(angles.shape + (3, 3))
    i = "xyz".index(axis)
    j, k = (i + 1) % 3, (i + 2) % 3
    m[..., i, i] = 1
    m[..., j, j], m[..., j, k], m[..., k, j], m[..., k, k] = c, -s, s, c
    return m


def matrices(angles: np.ndarray, axes: str) -> np.ndarray:
    """(..., 3, 3) rotations of angles (..., len(axes)) in radians about ``axes``
    (e.g. "xyz"), applied in that order about fixed axes: R = R_last ... R_first."""
    m = np.broadcast_to(np.eye(3), angles.shape[:-1] + (3, 3))
    for n, axis in enumerate(axes):
        m = _axis_matrices(axis, angles[..., n]) @ m
    return m


def angles(m: np.ndarray, axes: str) -> np.ndarray:
    """The angles (..., 3) in radians, about three distinct ``axes`` applied in
    order, of rotations (..., 3, 3); the middle angle in [-pi/2, pi/2]."""
    i, j, k = ("xyz".index(a) for a in axes)
    e = 1.0 if (j - i) % 3 == 1 else -1.0  # even or odd permutation of xyz
    middle = np.arcsin(np.clip(-e * m[..., k, i], -1.0, 1.0))
    first = np.arctan2(e * m[..., k, j], m[..., k, k])
    last = np.arctan2(e * m[..., j, i], m[..., i, i])
    return np.stack([first, middle, last], axis=-1)


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
