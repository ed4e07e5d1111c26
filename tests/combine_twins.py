"""Two slow twins of the combiner's C loop: vectorised numpy, and the thesis's per-frame Python loop."""

import numpy as np


def numpy_combine(old, new, plan, selected, offset_row=None, offsets=None, offset_channels=()):
    """The same per-frame rule as mt_combine, in whole-array numpy operations."""
    old_rows = old[np.maximum(plan.old_row, 0)] if old is not None else np.zeros((len(plan.weight), new.shape[1]))
    fresh = new[np.maximum(plan.new_row, 0)]
    following = fresh if plan.next_row is None else new[np.maximum(plan.next_row, 0)]
    a = np.zeros((len(plan.weight), 1)) if plan.ramp is None else plan.ramp[:, None]
    u = plan.weight[:, None]
    fresh = np.where(a == 0, fresh, (1 - a) * fresh + a * following)
    mixed = np.where(u == 0, old_rows, np.where(u == 1, fresh, (1 - u) * old_rows + u * fresh))
    out = np.where(selected.astype(bool), mixed, old_rows)
    if offset_row is not None:
        rows = offset_row >= 0
        out[np.ix_(rows, list(offset_channels))] += offsets[offset_row[rows]]
    return out


def python_combine(old, new, plan, selected):
    """The thesis's structure: a loop over output frames and channels in plain Python."""
    out = []
    old_rows, new_rows = plan.old_row.tolist(), plan.new_row.tolist()
    next_rows = new_rows if plan.next_row is None else plan.next_row.tolist()
    ramps = [0.0] * len(new_rows) if plan.ramp is None else plan.ramp.tolist()
    weights, chosen = plan.weight.tolist(), selected.tolist()
    for f in range(len(weights)):
        o = old[old_rows[f]] if old_rows[f] >= 0 else None
        n, m = new[new_rows[f]] if new_rows[f] >= 0 else None, new[next_rows[f]] if next_rows[f] >= 0 else None
        u, a = weights[f], ramps[f]
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
