"""Arrays of 3-vectors."""

from __future__ import annotations

import math

import numpy as np


def lengths(v: np.ndarray) -> np.ndarray:
    """The lengths of 3-vectors along the last axis: numpy's ``norm(v, axis=-1)``, the same
    numbers (the squares summed in the same order) in a sixth of its time, which reduces an
    axis of three element by element."""
    square = v * v
    return np.sqrt(square[..., 0] + square[..., 1] + square[..., 2])


def spans(v: np.ndarray) -> np.ndarray:
    """How far 3-vectors (n, 3) spread along each axis, (3,): numpy's ``ptp(v, axis=0)``, the
    same numbers in a fifth of its time (numpy reduces a long axis under a short one slowly)."""
    across = np.ascontiguousarray(v.T)
    return across.max(axis=1) - across.min(axis=1)


def median(x: np.ndarray) -> float:
    """The median of numbers (1-D), NaN where one is NaN: numpy's ``median``, the same number,
    in a fifth of its time on the few thousand a take holds."""
    n = len(x)
    if not n:
        return math.nan
    half = n // 2
    # the largest at the end as well: NaN sorts last
    ranked = np.partition(x, (half - 1, half, n - 1) if n % 2 == 0 else (half, n - 1))
    if math.isnan(ranked[-1]):
        return math.nan
    return float(ranked[half]) if n % 2 else (float(ranked[half - 1]) + float(ranked[half])) / 2
