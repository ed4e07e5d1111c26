"""Smoothing whole motions: median, mean and binomial (Pascal) filters over frames, per channel.

:class:`Smoother` holds everything a smoothing needs besides the frames
themselves, and the few facts about the whole take it depends on
(:class:`TakeStats`), so that a take too large for memory can be smoothed in
chunks (motiontheater.batch) to the same result, bit for bit, as whole.
"""

from __future__ import annotations

import functools
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Annotated, Literal

import numpy as np

import mtcore

from .motion import Motion
from .registry import Joints, register
from .skeleton import ROTATIONS, Skeleton

EdgeMode = Literal["nearest", "reflect", "mirror", "constant", "wrap"]

FILTERS = {
    "median": mtcore.median_filter1d,
    "mean": mtcore.uniform_filter1d,
    "binomial": mtcore.binomial_filter1d,
}


@dataclass
class TakeStats:
    """What smoothing needs to know about a whole take: each channel's range and its first frame."""

    low: np.ndarray
    high: np.ndarray
    first: np.ndarray

    @classmethod
    def of(cls, values: np.ndarray) -> TakeStats:
        """The statistics of the first frames of a take."""
        return cls(values.min(axis=0), values.max(axis=0), values[0].copy())

    def update(self, values: np.ndarray) -> None:
        """Widen the ranges by more frames of the same take."""
        np.minimum(self.low, values.min(axis=0), out=self.low)
        np.maximum(self.high, values.max(axis=0), out=self.high)


class Smoother:
    """A smoothing of a skeleton's channels; see :func:`filter_motion` for what it does.

    Frames go through in two steps: :meth:`unwrap` (sequential: it carries
    the whole turns counted so far) and :meth:`smooth` (any stretch of
    unwrapped frames; the result is exact for frames at least :attr:`halo`
    frames from either end of the stretch, unless that end is the take's).
    """

    def __init__(
        self,
        skeleton: Skeleton,
        kind: str,
        size: int,
        joints: Iterable[str] | None = None,
        *,
        translation: bool = True,
        mode: str = "nearest",
        workers: int | None = None,
    ):
        if kind not in FILTERS:
            raise ValueError(f"filter kind must be one of {', '.join(FILTERS)}, got {kind!r}")
        if isinstance(size, bool) or not isinstance(size, (int, np.integer)) or size < 1 or size % 2 == 0:
            raise ValueError(f"filter size must be an odd number of frames (3, 5, 7, ...), got {size!r}")
        self.kind, self.size, self.mode, self.workers = kind, int(size), mode, workers
        self.rotations: list[int] = []
        self.others: list[int] = []
        for joint in skeleton.joint_names if joints is None else tuple(joints):
            start = skeleton.first_column(joint)
            for i, dof in enumerate(skeleton.dofs(joint)):
                if dof in ROTATIONS:
                    self.rotations.append(start + i)
                elif translation:
                    self.others.append(start + i)
        self.period = skeleton.period

    @property
    def halo(self) -> int:
        """Frames either side of a frame that its smoothed value depends on."""
        return self.size // 2

    @property
    def block(self) -> int:
        """Stretches that start at multiples of this frame count smooth exactly as the whole take."""
        return mtcore.filters.lib.mt_filter1d_block(self.size)

    def unwrap(self, values: np.ndarray, previous: np.ndarray | None, turns: np.ndarray | None):
        """(values with rotation channels unwrapped, turns at the last frame).

        A jump of more than half a period between frames counts whole turns,
        and the angle gets turns times the period added: exact multiples, so
        that every chunking of a take unwraps to the same values.  ``previous``
        is the raw row before these frames and ``turns`` its count (None at
        the take's start).
        """
        out = values.copy()
        if not self.rotations:
            return out, turns
        raw = values[:, self.rotations]
        before = raw[:1] if previous is None else previous[None, self.rotations]
        steps = np.diff(raw, axis=0, prepend=before)
        jumps = np.where(np.abs(steps) > self.period / 2, -np.round(steps / self.period), 0.0)
        counted = np.cumsum(jumps, axis=0) + (0.0 if turns is None else turns)
        out[:, self.rotations] = raw + counted * self.period
        return out, counted[-1].copy() if len(counted) else turns

    def smooth(self, unwrapped: np.ndarray, stats: TakeStats) -> np.ndarray:
        """Smoothed frames (all channels; the chosen ones changed), rotations wrapped back."""
        values = unwrapped.copy()
        smooth = FILTERS[self.kind]
        for columns in (self.rotations, self.others):
            if not columns:
                continue
            block = unwrapped[:, columns]
            if self.kind == "median":
                values[:, columns] = smooth(block, self.size, axis=0, mode=self.mode, workers=self.workers)
            else:  # relative to the take's first frame: exact for constants, no loss far from zero
                base = stats.first[columns]
                values[:, columns] = (
                    smooth(block - base, self.size, axis=0, mode=self.mode, workers=self.workers) + base
                )
        if self.rotations:
            values[:, self.rotations] = _wrap_into(
                values[:, self.rotations], stats.low[self.rotations], stats.high[self.rotations], self.period
            )
        return values


def filter_motion(
    motion: Motion,
    kind: str,
    *,
    size: Annotated[int, "window length in frames (odd: 3, 5, 7, ...)"],
    joints: Annotated[Joints, "joints to smooth, comma-separated (default: all)"] = None,
    translation: Annotated[bool, "smooth the root's translation too (--no-translation leaves it)"] = True,
    mode: Annotated[EdgeMode, "how the edges are extended: nearest holds the edge value"] = "nearest",
    workers: Annotated[int | None, "threads (default: every core for large takes)"] = None,
) -> Motion:
    """A new motion whose channels are smoothed over frames by the filter ``kind``.

    The kinds are "median", "mean" (moving average) and "binomial" (Pascal
    weights, 1 2 1 / 4 for size 3), over an odd number of frames.  Only the
    chosen joints' channels change ("root" and bone names; all by default);
    every other channel stays bit-identical, and so does the root's
    translation when translation is off.  The edges are extended by the mode
    (nearest: the edge value held).  Rotation channels are unwrapped before smoothing, so that an angle crossing ±180° between frames is smoothed as the small step it is, and
    wrapped back after into the range the channel used, [-180, 180] or
    [0, 360] (or left continuous if it used neither).  Means are computed
    relative to each channel's first value, so a constant channel comes out
    exactly constant; the median only ever returns values of its window.
    """
    smoother = Smoother(motion.skeleton, kind, size, joints, translation=translation, mode=mode, workers=workers)
    chosen = smoother.rotations + smoother.others
    if not motion.frames or not chosen:
        return motion.replace(values=motion.values)
    unwrapped, _ = smoother.unwrap(motion.values, None, None)
    values = smoother.smooth(unwrapped, TakeStats.of(motion.values))
    values.flags.writeable = False
    return motion.replace(values=values)


def _wrap_into(filtered: np.ndarray, low: np.ndarray, high: np.ndarray, period: float) -> np.ndarray:
    """Each column of filtered in the range its take used: [-P/2, P/2], [0, P], or none."""
    half = period / 2
    centred = (low >= -half) & (high <= half)
    positive = ~centred & (low >= 0) & (high <= period)
    out = filtered.copy()
    c = filtered[:, centred]
    out[:, centred] = np.where(np.abs(c) <= half, c, c - period * np.floor((c + half) / period))
    p = filtered[:, positive]
    out[:, positive] = np.where((p >= 0) & (p <= period), p, p - period * np.floor(p / period))
    return out


for _kind, _what in (
    ("median", "moving median: removes spikes and marker pops, keeps steps"),
    ("mean", "moving average: evens out jitter"),
    ("binomial", "Pascal-weighted average (1 2 1 / 4 for size 3): the gentlest smoothing"),
):
    register(
        _kind,
        filter_motion,
        f"smooth with a {_what}",
        fixed={"kind": _kind},
        streamer=functools.partial(Smoother, kind=_kind),
    )
