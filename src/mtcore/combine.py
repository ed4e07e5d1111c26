"""The motion combiner's per-frame loop, in C (see ``mt_combine`` in mtcore.h).

Array level: motiontheater.combine works out the frame map; this runs it.
"""

from __future__ import annotations

import numpy as np

from . import _checks
from ._cdata import c_array
from ._mtcore import lib
from ._parallel import even_bounds, run_ranges, thread_count

__all__ = ["combine_frames"]

_PARALLEL_MIN_VALUES = 1 << 20


def combine_frames(
    old: np.ndarray | None,
    new: np.ndarray | None,
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
    workers: int | None = None,
) -> np.ndarray:
    """Output frames (len(weight), channels) from rows of ``old`` and ``new`` (see mt_combine).

    ``old`` and ``new`` are (frames, channels) motions, either (not both) None.  Per output
    frame (arrays of len(weight) entries): ``weight`` in [0, 1] is the new motion's share;
    ``old_row`` and ``new_row`` index the motions (-1: no frame, allowed only where the weight
    says the motion is not used; None: -1 throughout); ``ramp`` in [0, 1] interpolates the new
    motion towards row ``next_row`` (None: ``new_row``); ``offset_row`` picks a row of
    ``offsets`` (rows, len(offset_channels)) to add to the columns ``offset_channels`` (-1:
    none).  ``selected`` (channels,) marks the channels that take the new motion (None: all).
    Every argument is checked here, with a message naming it; the C loop checks again.
    """
    old = None if old is None else _checks.real(old, "old", (None, None))
    new = None if new is None else _checks.real(new, "new", (None, None))
    either = old if old is not None else new
    if either is None:
        raise ValueError("combine_frames needs an old or a new motion (or both), got None for both")
    channels = either.shape[1]
    if new is not None and new.shape[1] != channels:
        raise ValueError(f"new must have the {channels} channels of old, got shape {new.shape}")
    old_frames, new_frames = (0 if a is None else len(a) for a in (old, new))
    weight = _checks.fractions(weight, "weight", len(np.asarray(weight)) if np.ndim(weight) == 1 else -1)
    frames = len(weight)

    def rows(a, name: str, count: int) -> np.ndarray:
        if a is None:
            return np.full(frames, -1, np.int64)
        return _checks.integers(a, name, (frames,), -1, count)

    old_row, new_row = rows(old_row, "old_row", old_frames), rows(new_row, "new_row", new_frames)
    if ramp is None:  # no ramps: the C loop takes NULL for both
        if next_row is not None:
            raise ValueError("next_row is the row a ramp leads to: pass ramp too")
    else:
        ramp = _checks.fractions(ramp, "ramp", frames)
        next_row = new_row if next_row is None else rows(next_row, "next_row", new_frames)
    if selected is None:
        selected = np.ones(channels, np.uint8)
    else:
        selected = _checks.integers(selected, "selected", (channels,), 0, 2, np.uint8)
    offset_channels = _checks.integers(offset_channels, "offset_channels", (None,), 0, channels, np.uintp)
    width = len(offset_channels)
    offsets = np.zeros((0, width)) if offsets is None else _checks.real(offsets, "offsets", (None, width))
    offset_row = rows(offset_row, "offset_row", len(offsets))
    _check_rows_used(weight, ramp, selected, old_row, new_row, next_row)

    out = np.empty((frames, channels))
    bounds = even_bounds(frames, thread_count(workers, out.size >= _PARALLEL_MIN_VALUES))
    c_rows = "long long[]"
    args = (
        c_array(old),
        old_frames,
        c_array(new),
        new_frames,
        channels,
        frames,
        c_array(old_row, c_rows),
        c_array(new_row, c_rows),
        c_array(next_row, c_rows),
        c_array(ramp),
        c_array(weight),
        c_array(selected, "unsigned char[]"),
        c_array(offset_row, c_rows),
        c_array(offsets),
        len(offsets),
        c_array(offset_channels, "size_t[]"),
        width,
    )
    out_buf = c_array(out)

    run_ranges(lambda begin, end: lib.mt_combine(*args, begin, end, out_buf), bounds, "mt_combine")
    return out


def _check_rows_used(weight, ramp, selected, old_row, new_row, next_row) -> None:
    """Every row a frame reads must exist: old where its weight is below 1 (or a channel keeps the
    old motion), new where its weight is above 0, next_row where a ramp is above 0 too."""
    needs_old = (weight != 1) | (not selected.all())
    needs_new = weight != 0
    needs_next = needs_new & (ramp != 0) if ramp is not None else np.zeros_like(needs_new)
    for name, need, row, what in (
        ("old_row", needs_old, old_row, "a row of old"),
        ("new_row", needs_new, new_row, "a row of new"),
        ("next_row", needs_next, next_row, "the next row of new (its ramp is above 0)"),
    ):
        missing = need & (row < 0) if row is not None else np.zeros_like(need)
        if missing.any():
            f = int(np.flatnonzero(missing)[0])
            raise ValueError(f"output frame {f} (weight {float(weight[f])!r}) needs {what}, but {name}[{f}] is -1")
