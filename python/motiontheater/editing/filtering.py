"""Smoothing whole motions: median, mean and binomial (Pascal) filters over frames, per channel.

:class:`Smoother` holds everything a smoothing needs besides the frames
themselves, and the few facts about the whole take it depends on
(:class:`TakeStats`), so that a take too large for memory can be smoothed in
chunks (motiontheater.databases.batch) to the same result, bit for bit, as whole.
"""

from __future__ import annotations

import functools
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from functools import partial
from typing import Annotated, Literal

import numpy as np

import mtcore

from ..model.motion import Motion
from ..model.registry import Joints, register
from ..model.skeleton import ROTATIONS, Skeleton

EdgeMode = Literal["nearest", "reflect", "mirror", "constant", "wrap"]

FILTERS = {
    "median": mtcore.median_filter1d,
    "mean": mtcore.uniform_filter1d,
    "binomial": mtcore.binomial_filter1d,
}


@dataclass
class TakeStats:
    """What smoothing needs to know about a whole take: each channel's range and its first value,
    of its finite samples only (NaN where a channel has none yet)."""

    low: np.ndarray
    high: np.ndarray
    first: np.ndarray

    @classmethod
    def of(cls, values: np.ndarray) -> TakeStats:
        """The statistics of the first frames of a take."""
        return cls(*mtcore.rotations.finite_ranges(values))

    def update(self, values: np.ndarray) -> None:
        """Widen the ranges by more frames of the same take."""
        self.low, self.high, self.first = mtcore.rotations.finite_ranges(values, (self.low, self.high, self.first))

    @property
    def base(self) -> np.ndarray:
        """What the means are taken relative to: each channel's first finite value (0 for none)."""
        return np.where(np.isnan(self.first), 0.0, self.first)


@dataclass
class Unwrapping:
    """Where unwrapping stands after some frames: each rotation channel's last finite sample and
    the whole turns counted for it."""

    last: np.ndarray
    turns: np.ndarray


class Smoother:
    """A smoothing of a skeleton's channels; see :func:`filter_motion` for what it does.

    A :class:`~motiontheater.model.registry.Streamer`: frames go through in
    two steps, :meth:`prepare` (sequential: it unwraps the angles, carrying
    the whole turns counted so far) and :meth:`process` (any stretch of
    unwrapped frames; the result is exact for frames at least :attr:`halo`
    frames from either end of the stretch, unless that end is the take's),
    given the take's :class:`TakeStats` (:meth:`survey`).
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
        self.period = skeleton.period
        chosen_joints = None if joints is None else tuple(joints)
        self.rotations, self.others, self._chosen, self._turning = skeleton.derived(
            ("smoothed columns", chosen_joints, translation),
            lambda: _smoothed_columns(skeleton, chosen_joints, translation),
        )

    @property
    def halo(self) -> int:
        """Frames either side of a frame that its smoothed value depends on."""
        return self.size // 2

    @property
    def block(self) -> int:
        """Stretches that start at multiples of this frame count smooth exactly as the whole take."""
        return mtcore.filters.filter_block(self.size)

    def survey(self, values: np.ndarray, stats: TakeStats | None) -> TakeStats:
        """The statistics of the take so far, ``values`` (its next frames) added."""
        if stats is None:
            return TakeStats.of(values)
        stats.update(values)
        return stats

    def prepare(self, values: np.ndarray, state: Unwrapping | None) -> tuple[np.ndarray, Unwrapping | None]:
        """(values with rotation channels unwrapped by :func:`unwrap_angles`, the state after the last
        frame).  ``state`` is what the frames before these left (None at the take's start)."""
        if not len(self.rotations) or not len(values):
            return values.copy(), state
        return unwrap_angles(values, self.period, state, self.rotations)

    def process(self, unwrapped: np.ndarray, stats: TakeStats, *, scratch: bool = False) -> np.ndarray:
        """Smoothed frames (all channels; the chosen ones changed), rotations wrapped back.
        ``scratch``: the caller gives ``unwrapped`` up, and the means may work in its chosen
        columns rather than in a new array (the same values, an array fewer)."""
        chosen = self._chosen
        every = chosen == slice(0, unwrapped.shape[1])
        smooth = partial(FILTERS[self.kind], size=self.size, axis=0, mode=self.mode, workers=self.workers)
        if self.kind == "median":
            block = smooth(unwrapped[:, chosen])
        else:  # means relative to the take's first frame: exact for constants, no loss far from zero
            base = stats.base[chosen]
            if scratch:
                relative = unwrapped[:, chosen]  # a view where the columns run on
                relative -= base
            else:
                relative = unwrapped[:, chosen] - base
            block = smooth(relative)  # into a new array: in place costs a copy
            block += base
        if len(self._turning):
            rotations = self.rotations
            block = _wrap_into(block, stats.low[rotations], stats.high[rotations], self.period, self._turning)
        if every:
            return block
        values = unwrapped.copy()
        values[:, chosen] = block
        return values


def _smoothed_columns(
    skeleton: Skeleton, joints: Iterable[str] | None, translation: bool
) -> tuple[np.ndarray, list[int], slice | list[int], np.ndarray]:
    """The rotation and other columns that a smoothing of ``joints`` changes, all of them (as a
    slice where they run on, as a rule: no gather), and where the rotations are among them; the
    rotations' as index arrays (lists would be converted on every take)."""
    rotations: list[int] = []
    others: list[int] = []
    for column in skeleton.columns_of(joints):
        if skeleton.channels[column][1] in ROTATIONS:
            rotations.append(column)
        elif translation:
            others.append(column)
    chosen = sorted(rotations + others)
    runs_on = bool(chosen) and chosen == list(range(chosen[0], chosen[-1] + 1))
    where = {c: i for i, c in enumerate(chosen)}
    turning = np.array([where[c] for c in rotations], dtype=np.intp)
    chosen_columns = slice(chosen[0], chosen[-1] + 1) if runs_on else chosen
    return np.array(rotations, dtype=np.intp), others, chosen_columns, turning


def unwrap_angles(
    raw: np.ndarray, period: float, state: Unwrapping | None = None, columns: Sequence[int] | np.ndarray | None = None
) -> tuple[np.ndarray, Unwrapping]:
    """Angle columns (all, or ``columns``) of (frames, channels) unwrapped, in a new array, and the
    state after the last frame.

    A jump of more than half a period between frames counts whole turns,
    and the angle gets turns times the period added: exact multiples, so
    that every chunking of a take unwraps to the same values.  A sample
    that is not finite (inf, NaN) stays as it is and is stepped over: the
    next finite one is compared with the last finite one before it, so a
    bad sample spoils only the windows that hold it.  ``state`` is what
    the frames before these left (None at the take's start).  In C
    (:func:`mtcore.rotations.unwrap_angles`).
    """
    out, last, turns = mtcore.rotations.unwrap_angles(
        raw, period, columns, None if state is None else (state.last, state.turns)
    )
    return out, Unwrapping(last, turns)


def filter_motion(
    motion: Motion,
    kind: str,
    *,
    size: Annotated[int, "window length in frames (odd: 3, 5, 7, ...)"],
    joints: Annotated[Joints, "joints to smooth (default: all)"] = None,
    translation: Annotated[bool, "smooth the root's translation too"] = True,
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
    if not motion.frames or not (len(smoother.rotations) or smoother.others):
        return motion.replace(values=motion.values)
    unwrapped, _ = smoother.prepare(motion.values, None)
    values = smoother.process(unwrapped, TakeStats.of(motion.values), scratch=True)  # unwrapped is ours
    values.flags.writeable = False
    return motion.replace(values=values)


def _wrap_into(
    filtered: np.ndarray,
    low: np.ndarray,
    high: np.ndarray,
    period: float,
    columns: Sequence[int] | np.ndarray | None = None,
) -> np.ndarray:
    """Angle columns (all, or ``columns``) of filtered, each in the range its take used (the
    take's ``low`` .. ``high``, one per column): [-P/2, P/2], [0, P], or none.  Changed in place
    where it is a writeable C-contiguous float64 array (else a copy is); returned."""
    if not (filtered.dtype == np.float64 and filtered.flags.c_contiguous and filtered.flags.writeable):
        filtered = np.array(filtered, dtype=np.float64, order="C")
    mtcore.rotations.wrap_angles(filtered, low, high, period, columns)
    return filtered


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
