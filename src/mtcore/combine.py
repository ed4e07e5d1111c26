"""The motion combiner's per-frame loop, in C (see ``mt_combine`` in mtcore.h).

Array level: motiontheater.combine works out the frame map; this runs it.
"""

from __future__ import annotations

import numpy as np

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

    Per output frame: ``old_row`` and ``new_row`` index the motions (-1: none),
    ``weight`` is the new motion's share, ``next_row``/``ramp`` interpolate the
    new motion between two rows, ``offset_row`` picks a row of ``offsets``
    (columns ``offset_channels``) to add.  ``selected`` marks the channels
    that take the new motion.  The C loop checks that every row it reads exists.
    """
    given = old if old is not None else new
    if given is None:
        raise ValueError("combine_frames needs an old or a new motion")
    channels = given.shape[1]
    frames = len(weight)

    def ints(a):
        return np.full(frames, -1, np.int64) if a is None else np.ascontiguousarray(a, np.int64)

    old = None if old is None else np.ascontiguousarray(old, np.float64)
    new = None if new is None else np.ascontiguousarray(new, np.float64)
    for name, motion in (("old", old), ("new", new)):
        if motion is not None and (motion.ndim != 2 or motion.shape[1] != channels):
            raise ValueError(f"{name} must be (frames, {channels}), got {motion.shape}")
    old_row, new_row, offset_row = ints(old_row), ints(new_row), ints(offset_row)
    weight = np.ascontiguousarray(weight, np.float64)
    if ramp is None:  # no ramps: the C loop takes NULL for both
        next_row = None
    else:
        ramp = np.ascontiguousarray(ramp, np.float64)
        next_row = new_row if next_row is None else ints(next_row)
    for name, a in (
        ("old_row", old_row),
        ("new_row", new_row),
        ("next_row", next_row),
        ("ramp", ramp),
        ("offset_row", offset_row),
    ):
        if a is not None and a.shape != (frames,):
            raise ValueError(f"{name} must have one entry per output frame ({frames}), got shape {a.shape}")
    selected = np.ones(channels, np.uint8) if selected is None else np.ascontiguousarray(selected, np.uint8)
    offset_channels = np.ascontiguousarray(offset_channels, np.uintp)
    offsets = np.zeros((0, len(offset_channels))) if offsets is None else np.ascontiguousarray(offsets, np.float64)
    if offsets.ndim != 2 or offsets.shape[1] != len(offset_channels):
        raise ValueError(f"offsets must have one column per offset channel ({len(offset_channels)})")
    out = np.empty((frames, channels))
    bounds = even_bounds(frames, thread_count(workers, out.size >= _PARALLEL_MIN_VALUES))
    rows = "long long[]"
    args = (
        c_array(old),
        0 if old is None else len(old),
        c_array(new),
        0 if new is None else len(new),
        channels,
        frames,
        c_array(old_row, rows),
        c_array(new_row, rows),
        c_array(next_row, rows),
        c_array(ramp),
        c_array(weight),
        c_array(selected, "unsigned char[]"),
        c_array(offset_row, rows),
        c_array(offsets),
        len(offsets),
        c_array(offset_channels, "size_t[]"),
        len(offset_channels),
    )
    out_buf = c_array(out)

    run_ranges(lambda begin, end: lib.mt_combine(*args, begin, end, out_buf), bounds, "mt_combine")
    return out
