"""Slow, obvious twins of the C filters: pure Python over lists, one window at a time."""

from __future__ import annotations

import math

import numpy as np

MODES = ("reflect", "nearest", "mirror", "constant", "wrap")


def extend_index(r: int, n: int, mode: str) -> int | None:
    """Index into a line of length n of position r of its extension; None means cval."""
    if 0 <= r < n:
        return r
    if mode == "constant":
        return None
    if mode == "nearest":
        return 0 if r < 0 else n - 1
    if mode == "wrap":
        return r % n
    if mode == "reflect":  # d c b a | a b c d | d c b a
        m = r % (2 * n)
        return m if m < n else 2 * n - 1 - m
    if mode == "mirror":  # d c b | a b c d | c b a
        if n == 1:
            return 0
        m = r % (2 * n - 2)
        return m if m < n else 2 * n - 2 - m
    raise ValueError(mode)


def windows(line, size, mode, cval, origin):
    """The window of every output sample of a 1-d line, as lists of Python floats."""
    n = len(line)
    out = []
    for i in range(n):
        window = []
        for j in range(size):
            k = extend_index(i + j - size // 2 - origin, n, mode)
            window.append(cval if k is None else float(line[k]))
        out.append(window)
    return out


def median_line(line, size, mode="reflect", cval=0.0, origin=0):
    return [
        math.nan if any(math.isnan(v) for v in w) else sorted(w)[size // 2]
        for w in windows(line, size, mode, cval, origin)
    ]


def mean_line(line, size, mode="reflect", cval=0.0, origin=0):
    return [math.fsum(w) / size for w in windows(line, size, mode, cval, origin)]


def correlate_line(line, weights, mode="reflect", cval=0.0, origin=0):
    return [math.fsum(wt * v for wt, v in zip(weights, w)) for w in windows(line, len(weights), mode, cval, origin)]


def along_axis(fn, x: np.ndarray, axis: int, *args, **kwargs) -> np.ndarray:
    """Apply a line twin to every 1-d line of x along axis; float64 result."""
    x = np.asarray(x, dtype=np.float64)
    if x.size == 0:
        return x.copy()
    return np.apply_along_axis(lambda line: np.array(fn(list(line), *args, **kwargs)), axis, x)
