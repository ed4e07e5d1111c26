"""Twins of the rotation kernels (rotation.c) in plain numpy: products of single-axis matrices,
quaternion products, an eigenvector for a matrix's quaternion, per-frame loops for continuity."""

from __future__ import annotations

import math

import numpy as np

AXES = "xyz"


def axis_matrices(axis: str, angles) -> np.ndarray:
    """(..., 3, 3) rotations by angles (radians) about x, y or z."""
    angles = np.asarray(angles, dtype=float)
    c, s = np.cos(angles), np.sin(angles)
    m = np.zeros(angles.shape + (3, 3))
    i = AXES.index(axis)
    j, k = (i + 1) % 3, (i + 2) % 3
    m[..., i, i] = 1
    m[..., j, j], m[..., j, k], m[..., k, j], m[..., k, k] = c, -s, s, c
    return m


def matrices(angles: np.ndarray, axes: str) -> np.ndarray:
    """(..., 3, 3) rotations of angles (..., len(axes)) in radians about ``axes`` (e.g. "xyz"),
    applied in that order about fixed axes: R = R_last ... R_first."""
    angles = np.asarray(angles, dtype=float)
    m = np.broadcast_to(np.eye(3), angles.shape[:-1] + (3, 3))
    for n, axis in enumerate(axes):
        m = axis_matrices(axis, angles[..., n]) @ m
    return m


def euler_to_matrices(angles, order: str, extrinsic: bool, degrees: bool = False) -> np.ndarray:
    """Intrinsic angles about the turning axes i, j, k are extrinsic ones about k, j, i."""
    angles = np.radians(angles) if degrees else np.asarray(angles, dtype=float)
    return matrices(angles, order) if extrinsic else matrices(angles[..., ::-1], order[::-1])


def angles(m: np.ndarray, axes: str) -> np.ndarray:
    """The angles (..., 3) in radians, about three distinct ``axes`` applied in order, of
    rotations (..., 3, 3); the middle angle in [-pi/2, pi/2]."""
    return matrices_to_euler(m, axes, True)


def matrices_to_euler(m, order: str, extrinsic: bool, degrees: bool = False) -> np.ndarray:
    """Euler angles (..., 3) of rotations (..., 3, 3), R = R_k(c) R_j(b) R_i(a) (extrinsic).

    b from the angle between the last axis k and R e_i (which R_k(c) keeps); c turns
    R_j(b) e_i into R e_i about k; a is what is left, R_i(a) = (R_k(c) R_j(b))^T R.  At
    gimbal lock (R e_i along k) c is 0.  Intrinsic angles are extrinsic ones in reverse.
    """
    m = np.asarray(m, dtype=float)
    if degrees:
        return np.degrees(matrices_to_euler(m, order, extrinsic))
    if not extrinsic:
        return matrices_to_euler(m, order[::-1], True)[..., ::-1]
    i, j, k = (AXES.index(a) for a in order)
    column = m[..., :, i]
    if i == k:
        b = np.arccos(np.clip(column[..., i], -1.0, 1.0))
    else:
        e = 1.0 if (j - i) % 3 == 1 else -1.0
        b = np.arcsin(np.clip(-e * column[..., k], -1.0, 1.0))
    v = axis_matrices(order[1], b)[..., :, i]
    p, q = (k + 1) % 3, (k + 2) % 3
    locked = np.hypot(column[..., p], column[..., q]) < 1e-12
    c = np.where(locked, 0.0, np.arctan2(column[..., q], column[..., p]) - np.arctan2(v[..., q], v[..., p]))
    c = np.angle(np.exp(1j * c))  # into [-pi, pi]
    rest = np.swapaxes(axis_matrices(order[2], c) @ axis_matrices(order[1], b), -1, -2) @ m
    p, q = (i + 1) % 3, (i + 2) % 3
    a = np.arctan2(rest[..., q, p], rest[..., p, p])
    return np.stack([a, b, c], axis=-1)


def multiply(q: np.ndarray, r: np.ndarray) -> np.ndarray:
    """Hamilton products q r of quaternions (..., 4), (w, x, y, z)."""
    w1, v1 = q[..., :1], q[..., 1:]
    w2, v2 = r[..., :1], r[..., 1:]
    w = w1 * w2 - np.sum(v1 * v2, axis=-1, keepdims=True)
    return np.concatenate([w, w1 * v2 + w2 * v1 + np.cross(v1, v2)], axis=-1)


def quaternions_to_matrices(q) -> np.ndarray:
    """Column e of R is q e q* for the unit q: three quaternion products per rotation."""
    q = np.asarray(q, dtype=float)
    with np.errstate(invalid="ignore", divide="ignore"):
        u = q / np.linalg.norm(q, axis=-1, keepdims=True)
    conj = u * np.array([1.0, -1.0, -1.0, -1.0])
    columns = [multiply(multiply(u, np.broadcast_to(np.r_[0.0, e], u.shape)), conj)[..., 1:] for e in np.eye(3)]
    return np.stack(columns, axis=-1)


def matrices_to_quaternions(m) -> np.ndarray:
    """The eigenvector of the largest eigenvalue of Bar-Itzhack's symmetric 4x4 matrix, w >= 0."""
    m = np.asarray(m, dtype=float)
    flat = m.reshape(-1, 3, 3)
    out = np.empty((len(flat), 4))
    for n, r in enumerate(flat):
        k = (
            np.array(
                [
                    [r[0, 0] - r[1, 1] - r[2, 2], r[1, 0] + r[0, 1], r[2, 0] + r[0, 2], r[2, 1] - r[1, 2]],
                    [r[1, 0] + r[0, 1], r[1, 1] - r[0, 0] - r[2, 2], r[2, 1] + r[1, 2], r[0, 2] - r[2, 0]],
                    [r[2, 0] + r[0, 2], r[2, 1] + r[1, 2], r[2, 2] - r[0, 0] - r[1, 1], r[1, 0] - r[0, 1]],
                    [r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1], r[0, 0] + r[1, 1] + r[2, 2]],
                ]
            )
            / 3.0
        )
        x, y, z, w = np.linalg.eigh(k)[1][:, -1]
        out[n] = np.array([w, x, y, z]) * (-1.0 if w < 0 else 1.0)
    return out.reshape(m.shape[:-2] + (4,))


def quaternions_to_rotvecs(q) -> np.ndarray:
    """Axis times angle: the angle 2 atan2(|xyz|, w) of the unit quaternion with w >= 0."""
    q = np.asarray(q, dtype=float)
    q = q * np.where(q[..., :1] < 0, -1.0, 1.0)
    xyz = np.linalg.norm(q[..., 1:], axis=-1, keepdims=True)
    angle = 2 * np.arctan2(xyz, q[..., :1])
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(xyz > 0, q[..., 1:] / xyz * angle, 0.0 * q[..., 1:])


def rotvecs_to_quaternions(v) -> np.ndarray:
    """(cos(angle/2), sin(angle/2) axis), w made non-negative."""
    v = np.asarray(v, dtype=float)
    angle = np.linalg.norm(v, axis=-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        axis = np.where(angle > 0, v / angle, 0.0 * v)
    q = np.concatenate([np.cos(angle / 2), np.sin(angle / 2) * axis], axis=-1)
    return q * np.where(q[..., :1] < 0, -1.0, 1.0)


def unroll_quaternions(q, axis: int = 0) -> np.ndarray:
    """Each quaternion after the first negated where its dot product with the output before is negative."""
    q = np.moveaxis(np.asarray(q, dtype=float), axis, 0)
    out = q.copy()
    for t in range(1, len(q)):
        flip = np.sum(out[t - 1] * q[t], axis=-1, keepdims=True) < 0
        out[t] = np.where(flip, -q[t], q[t])
    return np.moveaxis(out, 0, axis)


def unroll_euler_line(angles, proper: bool, half: float) -> np.ndarray:
    """Every equivalent triple within a turn of the rounded shift, the nearest to the output
    before kept; a triple after one holding NaN kept as it is.  angles (frames, 3)."""
    angles = np.asarray(angles, dtype=float)
    out = angles.copy()
    shifts = 2 * half * np.array([(i, j, k) for i in (-1, 0, 1) for j in (-1, 0, 1) for k in (-1, 0, 1)])
    for t in range(1, len(angles)):
        a = angles[t]
        if np.isnan(out[t - 1]).any() or np.isnan(a).any():
            continue
        other = np.array([a[0] + half, (0 if proper else half) - a[1], a[2] + half])
        best = None
        for candidate in (a, other):
            base = candidate + 2 * half * np.round((out[t - 1] - candidate) / (2 * half))
            for s in shifts:
                d = np.sum((base + s - out[t - 1]) ** 2)
                if best is None or d < best[0]:
                    best = (d, base + s)
        out[t] = best[1]
    return out


def unroll_euler(angles, order: str, axis: int = 0, degrees: bool = False) -> np.ndarray:
    """unroll_euler_line along ``axis`` of angles (..., 3)."""
    a = np.moveaxis(np.asarray(angles, dtype=float), axis, 0)
    lines = a.reshape(len(a), -1, 3)
    half = 180.0 if degrees else np.pi
    out = np.stack([unroll_euler_line(lines[:, i], order[0] == order[2], half) for i in range(lines.shape[1])], 1)
    return np.moveaxis(out.reshape(a.shape), 0, axis)


def slerp(q0, q1, t) -> np.ndarray:
    """Textbook SLERP, sin((1 - t) theta) / sin theta q0 + sin(t theta) / sin theta q1, of the unit
    keys (q1 negated for the shorter arc), theta = arccos(q0 . q1); linear where theta is tiny."""
    q0, q1, t = np.broadcast_arrays(np.asarray(q0, float), np.asarray(q1, float), np.asarray(t, float)[..., None])
    a = q0 / np.linalg.norm(q0, axis=-1, keepdims=True)
    b = q1 / np.linalg.norm(q1, axis=-1, keepdims=True)
    b = np.where(np.sum(a * b, axis=-1, keepdims=True) < 0, -b, b)
    theta = np.arccos(np.clip(np.sum(a * b, axis=-1, keepdims=True), -1.0, 1.0))
    with np.errstate(invalid="ignore", divide="ignore"):
        curved = (np.sin((1 - t) * theta) * a + np.sin(t * theta) * b) / np.sin(theta)
    return np.where(theta < 1e-7, (1 - t) * a + t * b, curved)


def exp_map(v: np.ndarray) -> np.ndarray:
    """The quaternions (cos(|v|/2), sin(|v|/2) v/|v|) of rotation vectors, w of either sign."""
    angle = np.linalg.norm(v, axis=-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        axis = np.where(angle > 0, v / angle, 0.0 * v)
    return np.concatenate([np.cos(angle / 2), np.sin(angle / 2) * axis], axis=-1)


def interpolate_rotvecs(v0, v1, t, aligned: bool = False) -> np.ndarray:
    """v0 + t (v1 - v0); aligned: v0 first replaced by the rotation vector of -q0 where the keys'
    quaternions (exp_map) point apart, v0 (1 - 2 pi / |v0|) (2 pi about v1 when v0 is zero)."""
    v0, v1, t = np.broadcast_arrays(np.asarray(v0, float), np.asarray(v1, float), np.asarray(t, float)[..., None])
    if aligned:
        apart = np.sum(exp_map(v0) * exp_map(v1), axis=-1, keepdims=True) < 0
        a0 = np.linalg.norm(v0, axis=-1, keepdims=True)
        a1 = np.linalg.norm(v1, axis=-1, keepdims=True)
        with np.errstate(invalid="ignore", divide="ignore"):
            flipped = np.where(a0 > 0, v0 * (1 - 2 * np.pi / a0), v1 * (2 * np.pi / a1))
        v0 = np.where(apart, flipped, v0)
    return v0 + t * (v1 - v0)


def rotvecs_to_matrices(v) -> np.ndarray:
    """Through the quaternion of each rotation vector."""
    return quaternions_to_matrices(rotvecs_to_quaternions(v))


def _quaternions(m: np.ndarray) -> np.ndarray:
    """matrices_to_quaternions, NaN for a matrix holding NaN (which has no eigenvectors)."""
    bad = np.isnan(m).any(axis=(-2, -1))
    q = matrices_to_quaternions(np.where(bad[..., None, None], np.eye(3), m))
    q[bad] = np.nan
    return q


def interpolate_euler(k0, k1, t, order: str, extrinsic: bool, degrees: bool, blend: str, start=None, reference=None):
    """The chain of the twins above: the keys' quaternions (through matrices), SLERP or rotation
    vectors interpolated, back through matrices to Euler angles, then the path from ``start``
    (unroll_euler) or each angle's whole turns nearest ``reference``."""
    t = np.asarray(t, dtype=float)
    k0, k1 = (np.broadcast_to(np.asarray(k, dtype=float), (len(t),) + np.shape(k)[-2:]) for k in (k0, k1))
    q0, q1 = (_quaternions(euler_to_matrices(k, order, extrinsic, degrees)) for k in (k0, k1))
    if blend == "slerp":
        q = slerp(q0, q1, t[:, None])
    else:
        v0, v1 = quaternions_to_rotvecs(q0), quaternions_to_rotvecs(q1)
        q = rotvecs_to_quaternions(interpolate_rotvecs(v0, v1, t[:, None], aligned=blend == "aligned_expmap"))
    angles = matrices_to_euler(quaternions_to_matrices(q), order, extrinsic, degrees)
    turn = 360.0 if degrees else 2 * np.pi
    if start is not None:
        return unroll_euler(np.concatenate([np.asarray(start, dtype=float)[None], angles]), order, 0, degrees)[1:]
    if reference is not None:
        return angles + turn * np.round((np.asarray(reference, dtype=float) - angles) / turn)
    return angles


def sincos(x) -> tuple[np.ndarray, np.ndarray]:
    """numpy's sin and cos (NaN for infinities, quietly)."""
    with np.errstate(invalid="ignore"):
        return np.sin(x), np.cos(x)


def unwrap_angles(values, period: float, columns=None, state=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unwrapping sample by sample: each finite sample of a chosen column takes the whole turns
    that bring it within half a period of the last finite one before it; a sample that is not
    finite stays as it is; a column without turns is copied."""
    out = np.array(values, dtype=float)
    chosen = range(out.shape[1]) if columns is None else list(columns)
    last = np.full(len(chosen), np.nan) if state is None else np.array(state[0], dtype=float)
    turns = np.zeros(len(chosen)) if state is None else np.array(state[1], dtype=float)
    for k, c in enumerate(chosen):
        for t in range(out.shape[0]):
            v = out[t, c]
            if not np.isfinite(v):
                continue
            if np.isfinite(last[k]) and abs(v - last[k]) > period / 2:
                turns[k] -= np.round((v - last[k]) / period)
            last[k] = v
            if turns[k]:
                out[t, c] = v + turns[k] * period
    return out, last, turns


def wrap_angles(values, low, high, period: float, columns=None) -> np.ndarray:
    """Wrapping sample by sample, into a copy: a column whose take's range (low, high) fits in
    [-P/2, P/2] goes there, else one that fits in [0, P] there, else it is left as it is; a finite
    sample outside its range takes the whole turns that bring it to the range's start or above."""
    out = np.array(values, dtype=float)
    for k, c in enumerate(range(out.shape[1]) if columns is None else columns):
        if -period / 2 <= low[k] and high[k] <= period / 2:
            least = -period / 2
        elif 0 <= low[k] and high[k] <= period:
            least = 0.0
        else:
            continue
        for t in range(out.shape[0]):
            v = out[t, c]
            if math.isfinite(v) and (v < least or v > least + period):
                out[t, c] = v - period * math.floor((v - least) / period)
    return out


def finite_ranges(values, state=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each column's least, greatest and first finite sample, sample by sample, from ``state``."""
    values = np.asarray(values, dtype=float)
    channels = values.shape[1]
    low, high, first = (
        (np.full(channels, np.inf), np.full(channels, -np.inf), np.full(channels, np.nan))
        if state is None
        else tuple(np.array(x, dtype=float) for x in state)
    )
    for row in values:
        for c, v in enumerate(row):
            if math.isfinite(v):
                low[c], high[c] = min(low[c], v), max(high[c], v)
                if math.isnan(first[c]):
                    first[c] = v
    return low, high, first
