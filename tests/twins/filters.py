"""Twins of mt_filter1d: pure Python over lists, one window at a time, every window written out."""

from __future__ import annotations

import math

import numpy as np

MODES = ("reflect", "nearest", "mirror", "constant", "wrap")
KINDS = ("median", "uniform", "binomial")


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
    """The window of every output sample of a 1-d line, as lists of its values (and cval)."""
    n = len(line)
    out = []
    for i in range(n):
        window = []
        for j in range(size):
            k = extend_index(i + j - size // 2 - origin, n, mode)
            window.append(cval if k is None else line[k])
        out.append(window)
    return out


def _median(window: list[float]) -> float:
    return math.nan if any(math.isnan(v) for v in window) else sorted(window)[len(window) // 2]


def _sum(terms: list[float]) -> float:
    """The exact sum rounded once; NaN and infinities as IEEE arithmetic has them."""
    if any(math.isnan(v) for v in terms) or (math.inf in terms and -math.inf in terms):
        return math.nan
    if math.inf in terms or -math.inf in terms:
        return math.inf if math.inf in terms else -math.inf
    return math.fsum(terms)


def median_line(line, size, mode="reflect", cval=0.0, origin=0):
    return [_median(w) for w in windows(line, size, mode, cval, origin)]


def mean_line(line, size, mode="reflect", cval=0.0, origin=0):
    return [_sum(w) / size for w in windows(line, size, mode, cval, origin)]


def correlate_line(line, weights, mode="reflect", cval=0.0, origin=0):
    return [_sum([wt * v for wt, v in zip(weights, w)]) for w in windows(line, len(weights), mode, cval, origin)]


def along_axis(fn, x: np.ndarray, axis: int, *args, **kwargs) -> np.ndarray:
    """Apply a line twin to every 1-d line of x along axis; float64 result."""
    x = np.asarray(x, dtype=np.float64)
    if x.size == 0:
        return x.copy()
    return np.apply_along_axis(lambda line: np.array(fn(list(line), *args, **kwargs)), axis, x)


def pascal_weights(size: int) -> list[float]:
    """Row size - 1 of Pascal's triangle over its sum, each weight the correctly rounded fraction."""
    n = size - 1
    return [math.comb(n, k) / 2**n for k in range(size)]


def filter1d(kind: str, x, size: int, axis: int = -1, mode: str = "reflect", cval: float = 0.0, origin: int = 0):
    """The filter ``kind`` (one of KINDS) of x along axis, as mtcore's ``<kind>_filter1d``."""
    if kind == "median":
        return along_axis(median_line, x, axis, size, mode, cval, origin)
    if kind == "uniform":
        return along_axis(mean_line, x, axis, size, mode, cval, origin)
    return along_axis(correlate_line, x, axis, pascal_weights(size), mode, cval, origin)


def window_counts(lo: int, size: int, n: int, mode: str) -> dict[int | None, int]:
    """How many of the positions lo .. lo + size - 1 map to each sample (None: cval), by counting,
    for each position c of one period, the integers of the range congruent to it (any size)."""
    hi = lo + size - 1
    counts: dict[int | None, int] = {}
    if mode in ("nearest", "constant"):
        below, above = max(0, min(hi, -1) - lo + 1), max(0, hi - max(lo, n) + 1)
        for i in range(max(lo, 0), min(hi, n - 1) + 1):
            counts[i] = 1
        for r, times in ((-1, below), (n, above)):
            if times:
                k = extend_index(r, n, mode)
                counts[k] = counts.get(k, 0) + times
        return counts
    period = {"wrap": n, "reflect": 2 * n, "mirror": max(2 * n - 2, 1)}[mode]
    for c in range(period):
        times = (hi - c) // period - (lo - 1 - c) // period
        if times:
            k = extend_index(c, n, mode)
            counts[k] = counts.get(k, 0) + times
    return counts


def counted_line(kind: str, line, size: int, mode: str = "reflect", cval: float = 0.0, origin: int = 0) -> list:
    """median or uniform of a line with a window too long to write out (10**6, 2**40 samples):
    the window's samples counted (window_counts), the median found by walking them in order."""
    out = []
    for i in range(len(line)):
        counts = window_counts(i - size // 2 - origin, size, len(line), mode)
        pairs = [(cval if k is None else line[k], times) for k, times in counts.items()]
        if kind == "uniform":
            out.append(_sum([v * times for v, times in pairs]) / size)
        elif any(math.isnan(v) for v, _ in pairs):
            out.append(math.nan)
        else:
            seen = 0
            for v, times in sorted(pairs, key=lambda p: p[0]):
                seen += times
                if seen > size // 2:
                    out.append(v)
                    break
    return out
