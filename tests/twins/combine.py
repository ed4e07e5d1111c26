"""Twins of mt_combine: whole-array numpy, and the thesis's per-frame Python loop."""

from __future__ import annotations

import numpy as np


def combine_frames(
    old,
    new,
    old_row,
    new_row,
    weight,
    *,
    next_row=None,
    ramp=None,
    selected=None,
    offset_row=None,
    offsets=None,
    offset_channels=(),
) -> np.ndarray:
    """The per-frame rule of mt_combine (the arguments of mtcore.combine.combine_frames) in
    whole-array numpy operations."""
    new = np.asarray(new, float)
    weight = np.asarray(weight, float)
    frames, channels = len(weight), new.shape[1]
    old_rows = np.asarray(old, float)[np.maximum(old_row, 0)] if old is not None else np.zeros((frames, channels))
    fresh = new[np.maximum(new_row, 0)]
    following = fresh if ramp is None or next_row is None else new[np.maximum(next_row, 0)]
    a = np.zeros((frames, 1)) if ramp is None else np.asarray(ramp, float)[:, None]
    u = weight[:, None]
    fresh = np.where(a == 0, fresh, (1 - a) * fresh + a * following)
    mixed = np.where(u == 0, old_rows, np.where(u == 1, fresh, (1 - u) * old_rows + u * fresh))
    chosen = np.ones(channels, bool) if selected is None else np.asarray(selected).astype(bool)
    out = np.where(chosen, mixed, old_rows)
    if offset_row is not None:
        rows = np.asarray(offset_row) >= 0
        out[np.ix_(rows, list(offset_channels))] += np.asarray(offsets, float)[np.asarray(offset_row)[rows]]
    return out


def python_combine(old, new, old_row, new_row, weight, *, next_row=None, ramp=None, selected=None) -> list:
    """The thesis's structure: a loop over output frames and channels in plain Python (lists in, lists out)."""
    out = []
    next_row = new_row if ramp is None or next_row is None else next_row
    ramp = [0.0] * len(weight) if ramp is None else ramp
    chosen = [1] * len(new[0]) if selected is None else selected
    for f in range(len(weight)):
        o = old[old_row[f]] if old_row[f] >= 0 else None
        n, m = new[new_row[f]] if new_row[f] >= 0 else None, new[next_row[f]] if next_row[f] >= 0 else None
        u, a = weight[f], ramp[f]
        row = []
        for c in range(len(chosen)):
            if u == 0 or not chosen[c]:
                row.append(o[c])
                continue
            value = n[c] if a == 0 else (1 - a) * n[c] + a * m[c]
            row.append(value if u == 1 else (1 - u) * o[c] + u * value)
        out.append(row)
    return out


def python_thesis(old, new, old_first, new_first, cut, scale, windows, selected, offsets=None):
    """The thesis's MotionCombiner as a per-frame Python loop: the frame map worked out frame by
    frame inside the loop.  ``windows`` are (first, last, step, side) cross-fades; ``offsets`` a list
    of (first frame, last frame, {channel: value}) added (the literal preserve rule)."""
    (cf, ct), (sf, st) = cut, scale
    first, last = min(old_first, sf), max(old_first + len(old) - 1, st)
    out = []
    for i in range(first, last + 1):
        x = (2 * (cf * (st - sf) + (i - sf) * (ct - cf)) + (st - sf)) // (2 * (st - sf))
        u = 1.0 if sf <= i <= st else 0.0
        for w0, w1, step, side in windows:
            if w0 <= i <= w1:
                k = i - w0
                u = (k + 1) * step if side == "start" else 1.0 - (k + 1) * step
        o = old[min(max(i - old_first, 0), len(old) - 1)]
        n = new[min(max(x - new_first, 0), len(new) - 1)]
        row = []
        for c in range(len(o)):
            if u == 0 or not selected[c]:
                row.append(o[c])
            elif u == 1:
                row.append(n[c])
            else:
                row.append((1 - u) * o[c] + u * n[c])
        for f0, f1, add in offsets or ():
            if f0 <= i <= f1:
                for c, value in add.items():
                    row[c] += value
        out.append(row)
    return out
