"""Two slow twins of the combiner's C loop: vectorised numpy, and the thesis's per-frame Python loop."""

import numpy as np


def numpy_combine(old, new, plan, selected, offset_row=None, offsets=None, offset_channels=()):
    """The same per-frame rule as mt_combine, in whole-array numpy operations."""
    old_rows = old[np.maximum(plan.old_row, 0)] if old is not None else np.zeros((len(plan.weight), new.shape[1]))
    fresh = new[np.maximum(plan.new_row, 0)]
    following = new[np.maximum(plan.next_row, 0)]
    a, u = plan.ramp[:, None], plan.weight[:, None]
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
    old_rows, new_rows, next_rows = plan.old_row.tolist(), plan.new_row.tolist(), plan.next_row.tolist()
    ramps, weights, chosen = plan.ramp.tolist(), plan.weight.tolist(), selected.tolist()
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
