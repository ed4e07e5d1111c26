"""Euler angles and rotation matrices in plain numpy: the twin of mtcore's C conversions."""

import numpy as np


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


# The same conversions under mtcore.rotations' names and conventions, so that code written
# against mtcore.rotations can run on numpy alone (the combiner's numpy peer in benchmarks).


def euler_to_matrices(a, order: str, *, extrinsic: bool, degrees: bool = False) -> np.ndarray:
    a = np.radians(a) if degrees else np.asarray(a, float)
    return matrices(a, order) if extrinsic else matrices(a[..., ::-1], order[::-1])


def matrices_to_euler(m, order: str, *, extrinsic: bool, degrees: bool = False) -> np.ndarray:
    out = angles(m, order) if extrinsic else angles(m, order[::-1])[..., ::-1]
    return np.degrees(out) if degrees else out


def rotvecs_to_matrices(v) -> np.ndarray:
    """Rodrigues' formula."""
    v = np.asarray(v, float)
    angle = np.linalg.norm(v, axis=-1)[..., None, None]
    axis = v / np.where(angle[..., 0] > 0, angle[..., 0], 1.0)
    k = np.zeros(v.shape[:-1] + (3, 3))
    k[..., 0, 1], k[..., 0, 2], k[..., 1, 2] = -axis[..., 2], axis[..., 1], -axis[..., 0]
    k = k - np.swapaxes(k, -1, -2)
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * (k @ k)
