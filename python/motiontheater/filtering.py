"""Smoothing whole motions: median, mean and binomial (Pascal) filters over frames, per channel."""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

import mtcore

from .motion import Motion
from .skeleton import ROTATIONS

FILTERS = {
    "median": mtcore.median_filter1d,
    "mean": mtcore.uniform_filter1d,
    "binomial": mtcore.binomial_filter1d,
}


def filter_motion(
    motion: Motion,
    kind: str,
    size: int,
    joints: Iterable[str] | None = None,
    *,
    translation: bool = True,
    mode: str = "nearest",
    workers: int | None = None,
) -> Motion:
    """A new motion whose channels are smoothed over frames.

    ``kind`` is "median", "mean" (moving average) or "binomial" (Pascal
    weights, 1 2 1 / 4 for size 3), ``size`` an odd number of frames.
    ``joints`` names the joints to smooth ("root" and bone names; all by
    default); every other channel stays bit-identical.  ``translation=False``
    leaves translation channels (the root's position) alone.  ``mode`` is
    the edge mode of :mod:`mtcore` ("nearest": hold the edge value).

    Rotation channels are unwrapped before smoothing, so that an angle
    crossing ±180° between frames is smoothed as the small step it is, and
    wrapped back after into the range the channel used, [-180, 180] or
    [0, 360] (or left continuous if it used neither).  Means are computed
    relative to each channel's first value, so a constant channel comes out
    exactly constant; the median only ever returns values of its window.
    """
    if kind not in FILTERS:
        raise ValueError(f"filter kind must be one of {', '.join(FILTERS)}, got {kind!r}")
    if isinstance(size, bool) or not isinstance(size, (int, np.integer)) or size < 1 or size % 2 == 0:
        raise ValueError(f"filter size must be an odd number of frames (3, 5, 7, ...), got {size!r}")
    skeleton = motion.skeleton
    chosen = skeleton.joint_names if joints is None else tuple(joints)
    rotations, others = [], []
    for joint in chosen:
        for dof, column in zip(skeleton.dofs(joint), motion.columns(joint)):
            if dof in ROTATIONS:
                rotations.append(column)
            elif translation:
                others.append(column)
    values = motion.values.copy()
    smooth = FILTERS[kind]

    def run(block: np.ndarray) -> np.ndarray:
        if kind == "median" or not len(block):
            return smooth(block, size, axis=0, mode=mode, workers=workers)
        base = block[:1]  # exact for constants, and no loss for channels far from zero
        return smooth(block - base, size, axis=0, mode=mode, workers=workers) + base

    if rotations:
        period = 360.0 if skeleton.angle_unit == "deg" else 2 * np.pi
        block = values[:, rotations]
        values[:, rotations] = _wrap_like(run(np.unwrap(block, period=period, axis=0)), block, period)
    if others:
        values[:, others] = run(values[:, others])
    values.flags.writeable = False
    return motion.replace(values=values)


def _wrap_like(filtered: np.ndarray, original: np.ndarray, period: float) -> np.ndarray:
    """Each column of filtered in the range its original used: [-P/2, P/2], [0, P], or none."""
    half = period / 2
    if not len(original):
        return filtered
    low, high = original.min(axis=0), original.max(axis=0)
    centred = (low >= -half) & (high <= half)
    positive = ~centred & (low >= 0) & (high <= period)
    out = filtered.copy()
    c = filtered[:, centred]
    out[:, centred] = np.where(np.abs(c) <= half, c, c - period * np.floor((c + half) / period))
    p = filtered[:, positive]
    out[:, positive] = np.where((p >= 0) & (p <= period), p, p - period * np.floor(p / period))
    return out
