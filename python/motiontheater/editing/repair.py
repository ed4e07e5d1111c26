"""Repairs that the take check's recipes call for, besides the filters: Euler angles made
continuous again (``unroll``), lengths rescaled (``scale``) and a frame rate set right
(``retime``)."""

from __future__ import annotations

from typing import Annotated

import numpy as np

from mtcore.rotations import unroll_euler

from ..model.motion import Motion
from ..model.registry import Frames, Joints, step
from ..model.skeleton import ROTATIONS


@step(
    "unroll",
    "make Euler angles continuous: each frame the triple of its rotation nearest the frame before",
    frames="own",
)
def unroll(
    motion: Motion,
    *,
    joints: Annotated[Joints, "joints to unroll (default: all)"] = None,
    frames: Annotated[
        Frames, "unroll frames FIRST..LAST only, from the frame before them (frame numbers; default: all)"
    ] = None,
) -> Motion:
    """A new motion whose Euler angles take no jump that is not a turn: each frame's triple of a
    joint with three rotation channels becomes, of the triples of the same rotation, the one
    nearest the frame before (the other solution (a + 180, 180 - b, c + 180), and whole turns);
    other rotation channels move by whole turns.  The rotations, and so every position, stay
    as they were.  With ``frames``, the frames before them are kept and the range continues
    from the frame before it; the frames after it are kept too."""
    skeleton = motion.skeleton
    first, last = 0, motion.frames - 1
    if frames is not None:
        if not motion.first_frame <= frames[0] <= frames[1] <= motion.last_frame:
            raise ValueError(
                f"frames {frames[0]}:{frames[1]} are not within the motion's frames "
                f"{motion.first_frame}..{motion.last_frame}"
            )
        first, last = frames[0] - motion.first_frame, frames[1] - motion.first_frame
    start = max(first - 1, 0)  # the frame the range continues from, kept as it is
    rows = slice(start, last + 1)
    values = motion.values.copy()
    degrees = skeleton.angle_unit == "deg"
    triples = set()
    for order, _, columns in skeleton.euler_groups(joints):
        for row in columns:
            values[rows, row] = unroll_euler(values[rows, row], order, degrees=degrees)
            triples.update(row.tolist())
    others = [c for c in skeleton.columns_of(joints) if motion.channels[c][1] in ROTATIONS and c not in triples]
    if others:
        block = values[rows, others]
        finite = np.isfinite(block).all(axis=1)
        block[finite] = np.unwrap(block[finite], axis=0, period=skeleton.period)
        values[rows, others] = block
    values.flags.writeable = False
    return motion.replace(values=values)


@step(
    "scale",
    "multiply every length (bones, offsets, translations) by a factor: a unit off by a known factor",
    frames="none",
)
def scale(
    motion: Motion, *, factor: Annotated[float, "the factor, e.g. 10 for lengths written in cm as if mm"]
) -> Motion:
    """A new motion whose skeleton and translations are ``factor`` times as long, in the same
    unit: the repair for a take whose lengths were written in another unit than its file says."""
    if not (np.isfinite(factor) and factor > 0):
        raise ValueError(f"factor must be a positive number, got {factor!r}")
    return motion.with_units(length_factor=factor)


@step("retime", "set the frame rate, the frames kept as they are: a Frame Time written for another rate", frames="none")
def retime(
    motion: Motion, *, rate: Annotated[float, "the rate the take was recorded at, in Hz (frames per second)"]
) -> Motion:
    """A new motion of the same frames at ``rate`` Hz: the repair for a take whose file gives
    another rate than it was recorded at (its motion too slow or too fast).  ``resample``
    changes the frames to keep the motion's timing instead."""
    if isinstance(rate, bool) or not (isinstance(rate, (int, float)) and np.isfinite(rate) and rate > 0):
        raise ValueError(f"rate must be a positive number of frames per second, got {rate!r}")
    return motion.replace(frame_rate=float(rate))
