"""The take check's channel pass: gaps, frozen runs, spikes, steps and repeated rows in one pass
(the kernel ``mt_check_channels``), and the pace of each step, for rows missing between two
(``mt_check_pace``).  What the events mean for a take, in its units and joints,
is :mod:`motiontheater.databases.check`'s."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from . import _checks
from ._cdata import c_array
from ._mtcore import ffi, lib
from ._status import check

__all__ = [
    "FROZEN",
    "GAP",
    "KINDS",
    "REPEAT",
    "SPIKE",
    "STEP",
    "ChannelEvents",
    "LegCheck",
    "LegMeasures",
    "Pace",
    "channel_events",
    "elbow_bends",
    "leg_measures",
    "pace",
    "roughness",
    "seen_runs",
    "trim_runs",
]

GAP, FROZEN, SPIKE, STEP, REPEAT = (
    lib.MT_CHECK_GAP,
    lib.MT_CHECK_FROZEN,
    lib.MT_CHECK_SPIKE,
    lib.MT_CHECK_STEP,
    lib.MT_CHECK_REPEAT,
)
KINDS = {GAP: "gap", FROZEN: "frozen", SPIKE: "spike", STEP: "step", REPEAT: "repeat"}
"""The kind codes of the events, named."""
_CODES = np.array(sorted(KINDS))


@dataclass(frozen=True)
class ChannelEvents:
    """What the pass found.  ``events`` (n, 5) intp rows of channel, first row, last row
    (inclusive), kind and the row where ``sizes`` peaks, sorted by channel, first row and kind;
    repeated rows have channel ``channels``.  ``roughness`` and ``smooth_rows`` per channel: the
    sum of squared residuals from the mean of the two neighbours over the rows where that stays
    within the spike limit, and how many rows that was."""

    events: np.ndarray
    sizes: np.ndarray
    roughness: np.ndarray
    smooth_rows: np.ndarray

    def by_kind(self) -> dict[int, tuple[np.ndarray, np.ndarray]]:
        """The events and their sizes of each kind (every code of KINDS, in its order), each
        kind's in the order they come."""
        kinds = self.events[:, 3]
        order = np.argsort(kinds, kind="stable")  # one sort in place of a mask a kind
        bounds = np.searchsorted(kinds[order], _CODES).tolist() + [len(kinds)]
        events, sizes = self.events[order], self.sizes[order]
        return {code: (events[a:b], sizes[a:b]) for code, a, b in zip(_CODES.tolist(), bounds, bounds[1:])}


def channel_events(
    values: ArrayLike,
    spike_limit: ArrayLike,
    step_limit: ArrayLike,
    min_run: int,
    begin: int = 0,
    end: int | None = None,
) -> ChannelEvents:
    """The events of the (rows, channels) values' rows ``begin`` .. ``end - 1`` (the others are
    read as neighbours): runs of NaN, runs of at least ``min_run`` equal values, samples farther
    than ``spike_limit`` (one per channel, or one for all) from the median of the five around
    them, changes farther than ``step_limit`` from both changes beside them, and rows that repeat
    the row before in every channel.  The kinds and sizes are those of ``mt_check_channels``
    (csrc/mtcore.h)."""
    x = _table(values)
    rows, channels = x.shape
    spikes = _limits(spike_limit, channels, "spike_limit")
    steps = _limits(step_limit, channels, "step_limit")
    min_run = _checks.integer(min_run, "min_run", 1)
    begin = _checks.integer(begin, "begin", 0, rows)
    end = rows if end is None else _checks.integer(end, "end", begin, rows)
    roughness = np.zeros(channels)
    smooth = np.zeros(channels, dtype=np.uintp)
    count = ffi.new("size_t *")
    capacity = 64 + rows  # seldom outgrown: a second pass over the values costs as much as the first
    while True:
        events = np.empty((capacity, 5), dtype=np.uintp)  # the kernel writes the first count rows
        sizes = np.empty(capacity)
        status = lib.mt_check_channels(
            c_array(x), rows, channels, channels, begin, end, c_array(spikes), c_array(steps), min_run,
            c_array(events, "size_t[]"), c_array(sizes), capacity, count, c_array(roughness),
            c_array(smooth, "size_t[]"),
        )  # fmt: skip
        check(status, "mt_check_channels")
        if count[0] <= capacity:
            break
        capacity = count[0]
    events, sizes = events[: count[0]].astype(np.intp), sizes[: count[0]]
    order = np.lexsort((events[:, 3], events[:, 1], events[:, 0]))
    return ChannelEvents(events[order], sizes[order], roughness, smooth.astype(np.intp))


def _table(values: ArrayLike) -> np.ndarray:
    """The (rows, channels) values as a C-contiguous float64 array."""
    x = np.ascontiguousarray(values, dtype=np.float64)
    if x.ndim != 2:
        raise ValueError(f"values must be two-dimensional (rows, channels), got shape {x.shape}")
    return x


def _limits(limit: ArrayLike, channels: int, name: str) -> np.ndarray:
    a = np.asarray(limit, dtype=np.float64)
    if a.ndim == 0:
        a = np.full(channels, float(a))
    if a.shape != (channels,):
        raise ValueError(f"{name} must be a number or one per channel ({channels}), got shape {a.shape}")
    if np.isnan(a).any() or (a < 0).any():
        raise ValueError(f"{name} must be non-negative numbers, got {a[np.isnan(a) | (a < 0)][0]}")
    return np.ascontiguousarray(a)


@dataclass(frozen=True)
class Pace:
    """How far each step of a take moves against the steps beside it, as weighted sums over the
    channels of m, the mean of the changes into row t and out of row t + 1, and d, the change from
    row t to row t + 1: ``moved`` of m^2, ``paced`` of d m and ``stepped`` of d^2, each (rows,).
    paced / moved is how many steps of motion the step holds (2: a row missing), and stepped
    - 2 s paced + s^2 moved how far it lies from s of them.  0 where a step has no steps on
    both sides."""

    moved: np.ndarray
    paced: np.ndarray
    stepped: np.ndarray


def pace(values: ArrayLike, weight: ArrayLike) -> Pace:
    """The :class:`Pace` of the (rows, channels) values' steps, each channel weighted by
    ``weight`` (one per channel, or one for all: 1 / the variance of a step's change less the
    mean of the changes beside it, from noise).  The kernel ``mt_check_pace`` (csrc/mtcore.h)."""
    x = _table(values)
    rows, channels = x.shape
    w = _limits(weight, channels, "weight")
    if not np.isfinite(w).all():
        raise ValueError(f"weight must be finite, got {w[~np.isfinite(w)][0]}")
    moved, paced, stepped = np.zeros(rows), np.zeros(rows), np.zeros(rows)
    status = lib.mt_check_pace(c_array(x), rows, channels, channels, c_array(w), c_array(moved),
                               c_array(paced), c_array(stepped))  # fmt: skip
    check(status, "mt_check_pace")
    return Pace(moved, paced, stepped)


@dataclass(frozen=True)
class LegCheck:
    """What :func:`leg_measures` needs besides the legs: the floor (a point p lies p . (up -
    slope) - level above it; ``up`` a unit vector, ``slope`` perpendicular to it), the unit
    (``meters_per_unit``) and rate (Hz), and the limits, physical: a foot point is on the floor
    less than ``floor_height`` metres above its lowest over the ``window`` frames before and
    after, and slower than ``floor_speed`` m/s across up; a knee's backwards bend is told where
    the foot lies across the shin (their cosine under ``foot_across``) and the bend is under
    ``folded`` degrees."""

    up: tuple[float, float, float]
    slope: tuple[float, float, float]
    level: float
    meters_per_unit: float
    frame_rate: float
    window: int
    floor_height: float
    floor_speed: float
    foot_across: float
    folded: float

    def as_struct(self):
        """The settings as the kernel takes them (``struct mt_leg_check``)."""
        up, slope = [float(v) for v in self.up], [float(v) for v in self.slope]
        if len(up) != 3 or not abs(math.hypot(*up) - 1) <= 1e-9:
            raise ValueError(f"up must be a unit vector of 3, got {self.up}")
        if len(slope) != 3 or not abs(sum(a * b for a, b in zip(slope, up))) <= 1e-9:
            raise ValueError(f"slope must be a finite vector of 3 perpendicular to up, got {self.slope}")
        for name in _NUMBERS:
            if not math.isfinite(getattr(self, name)):
                raise ValueError(f"{name} must be finite, got {getattr(self, name)}")
        if not (self.meters_per_unit > 0 and self.frame_rate > 0):
            raise ValueError(
                f"meters_per_unit and frame_rate must be positive, got {self.meters_per_unit}, {self.frame_rate}"
            )
        settings = ffi.new("struct mt_leg_check *")
        settings.up, settings.slope = up, slope
        settings.window = _checks.integer(self.window, "window", 0)
        for name in _NUMBERS:
            setattr(settings, name, float(getattr(self, name)))
        return settings


_NUMBERS = ("level", "meters_per_unit", "frame_rate", "floor_height", "floor_speed", "foot_across", "folded")
"""The settings of :class:`LegCheck` that are single numbers."""


@dataclass(frozen=True)
class LegMeasures:
    """The legs frame by frame, as ``mt_check_legs`` (csrc/mtcore.h) measures them, in the
    points' unit and degrees: ``drift`` (legs, 2, frames) of heel and ball, how far the point has
    moved across up since its run of frames on the floor began (NaN off the floor); ``depth``
    (legs, frames), how far the lowest of heel, ball and toe tip lies below where it rests;
    ``back`` (legs, frames), how far the knee bends backwards (0: it does not, or cannot tell);
    ``standing`` (6,), how many of the legs' frames stand (hip above ankle) along +x, -x, +y, -y,
    +z and -z."""

    drift: np.ndarray
    depth: np.ndarray
    back: np.ndarray
    standing: np.ndarray


def leg_measures(
    points: ArrayLike, hips: ArrayLike, rest: ArrayLike, tips: ArrayLike, settings: LegCheck
) -> LegMeasures:
    """The :class:`LegMeasures` of legs given as ``points`` (legs, frames, 5, 3: knee, ankle,
    ball, heel, toe tip; :func:`mtcore.footskate.leg_points`) and ``hips`` (legs, frames, 3),
    their feet resting at heights ``rest`` (legs, 3: heel, ball, tip) above the floor, ``tips``
    (legs) telling which legs have a toe tip."""
    p = _checks.real(points, "points", (None, None, 5, 3))
    legs, frames = p.shape[:2]
    h = _checks.real(hips, "hips", (legs, frames, 3))
    r = _checks.real(rest, "rest", (legs, 3))
    t = _checks.flags(tips, "tips", legs)
    struct = settings.as_struct()
    drift, depth, back = np.empty((legs, 2, frames)), np.empty((legs, frames)), np.empty((legs, frames))
    standing = np.empty(6, np.uintp)
    status = lib.mt_check_legs(c_array(p), c_array(h), legs, frames, c_array(r), c_array(t, "int[]"), struct,
                               c_array(drift), c_array(depth), c_array(back), c_array(standing, "size_t[]"))  # fmt: skip
    check(status, "mt_check_legs")
    return LegMeasures(drift, depth, back, standing)


def elbow_bends(
    positions: ArrayLike,
    world: ArrayLike,
    turning: ArrayLike,
    placing: ArrayLike,
    bent_deg: float,
    least: float,
    hinge: float,
) -> tuple[np.ndarray, np.ndarray]:
    """How far each arm's elbow bends, frame by frame, forward positive and backwards negative,
    in degrees (arms, frames), about the axis the frames bent past ``bent_deg`` share, and whether
    the take tells that axis (arms,): at least max(2, ``least``) such frames whose turns share it
    by more than ``hinge`` (NaN bends where it does not; ``mt_check_elbows``, csrc/mtcore.h).
    ``positions`` (frames, joints, 3) and ``world`` (frames, turned, 3, 3) of the joints,
    ``turning`` (arms) the world rotation each upper arm turns with, ``placing`` (arms, 3) the
    joints where its shoulder, elbow and wrist are."""
    p = _checks.real(positions, "positions", (None, None, 3))
    frames, joints = p.shape[:2]
    w = _checks.real(world, "world", (frames, None, 3, 3))
    turned = _checks.integers(turning, "turning", (None,), 0, w.shape[1], np.uintp)
    arms = len(turned)
    place = _checks.integers(placing, "placing", (arms, 3), 0, joints, np.uintp)
    if not 0 < bent_deg < 90:
        raise ValueError(f"bent_deg must lie between 0 and 90, got {bent_deg}")
    if not (least >= 0 and 0 <= hinge <= 1):
        raise ValueError(f"least must be >= 0 and hinge within 0 .. 1, got {least}, {hinge}")
    bend, judged = np.empty((arms, frames)), np.zeros(arms, np.uint8)
    status = lib.mt_check_elbows(c_array(p), frames, joints, c_array(w), w.shape[1], c_array(turned, "size_t[]"),
                                 c_array(place, "size_t[]"), arms, math.tan(math.radians(bent_deg)), float(least),
                                 float(hinge), c_array(bend), c_array(judged, "unsigned char[]"))  # fmt: skip
    check(status, "mt_check_elbows")
    return bend, judged.view(bool)


def trim_runs(
    quaternions: ArrayLike, first: ArrayLike, last: ArrayLike, limits: ArrayLike
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Candidate spikes of one joint's rotation, ``quaternions`` (frames, 4) unit, over frames
    first .. last (runs,) each, trimmed of the ends that lie within ``limits`` (runs,) degrees of
    the path between the frames around them, one frame at a time (``mt_check_trim``,
    csrc/mtcore.h): the frames left (first, last) and the most degrees any of them lies off that
    path (NaN for a run at an end of the take or beside a NaN, left whole)."""
    q = _checks.real(quaternions, "quaternions", (None, 4))
    frames = len(q)
    b = _checks.integers(last, "last", (None,), 0, frames, np.uintp)
    a = _checks.integers(first, "first", (len(b),), 0, frames, np.uintp)
    if (a > b).any():
        raise ValueError("each run's first frame must not follow its last")
    bound = _checks.real(limits, "limits", (len(b),))
    out = np.empty((2, len(b)), np.uintp), np.empty(len(b))
    status = lib.mt_check_trim(c_array(q), frames, len(b), c_array(a, "size_t[]"), c_array(b, "size_t[]"),
                               c_array(bound), c_array(out[0][0], "size_t[]"), c_array(out[0][1], "size_t[]"),
                               c_array(out[1]))  # fmt: skip
    check(status, "mt_check_trim")
    return out[0][0], out[0][1], out[1]


def seen_runs(
    places: ArrayLike,
    world: ArrayLike,
    joint: int,
    origin: int,
    axis: ArrayLike,
    points: ArrayLike,
    quaternions: ArrayLike,
    first: ArrayLike,
    last: ArrayLike,
    meters: float,
    keys: tuple[ArrayLike, ArrayLike] | None = None,
    row: int | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """What runs of rows first .. last (1 <= first <= last <= frames - 2) of a joint's rotation
    move (``mt_check_seen``, csrc/mtcore.h), from the take's ``places`` (frames, joints, 3) and
    ``world`` rotations (frames, turned, 3, 3; the joint's at ``row``, by default every joint's
    and the joint's own index): the ``points`` it turns (joint indices, offsets
    from joint ``origin``'s place) about its world rotation times ``axis`` (3, 3), its rotation
    at each frame ``quaternions`` (frames, 4): how far they lie off midway between the rows
    around, and how far from where the SLERP between the rows ``keys`` (before, after; by
    default those around the run) would put them, in metres (``meters`` a unit), per run."""
    p = _checks.real(places, "places", (None, None, 3))
    frames, joints = p.shape[:2]
    w = _checks.real(world, "world", (frames, None if row is not None else joints, 3, 3))
    q = _checks.real(quaternions, "quaternions", (frames, 4))
    c = _checks.real(axis, "axis", (3, 3))
    chosen = _checks.integers(points, "points", (None,), 0, joints, np.uintp)
    b = _checks.integers(last, "last", (None,), 1, max(frames - 1, 1), np.uintp)
    a = _checks.integers(first, "first", (len(b),), 1, max(frames - 1, 1), np.uintp)
    if (a > b).any():
        raise ValueError("each run's first row must not follow its last")
    before, after = (a - 1, b + 1) if keys is None else keys
    k0 = _checks.integers(before, "keys[0]", (len(b),), 0, frames, np.uintp)
    k1 = _checks.integers(after, "keys[1]", (len(b),), 0, frames, np.uintp)
    if (k0 >= k1).any():
        raise ValueError("each run's first key row must come before its second")
    turned: Any = ffi.new("struct mt_turned *")  # structs: fields by name
    held = c_array(p), c_array(w), c_array(c), c_array(chosen, "size_t[]")  # alive through the call
    turned.places, turned.world, turned.axis, turned.points = held
    turned.frames, turned.joints, turned.count = frames, joints, len(chosen)
    turned.joint = _checks.integer(joint, "joint", 0, joints - 1)
    turned.origin = _checks.integer(origin, "origin", 0, joints - 1)
    turned.turned = w.shape[1]
    turned.row = turned.joint if row is None else _checks.integer(row, "row", 0, w.shape[1] - 1)
    off, filled = np.empty(len(b)), np.empty(len(b))
    status = lib.mt_check_seen(turned, c_array(q), len(b), c_array(a, "size_t[]"), c_array(b, "size_t[]"),
                               c_array(k0, "size_t[]"), c_array(k1, "size_t[]"), float(meters), c_array(off),
                               c_array(filled))  # fmt: skip
    check(status, "mt_check_seen")
    return off, filled


def roughness(values: ArrayLike, squares: np.ndarray, counts: np.ndarray) -> None:
    """Add to ``squares`` and ``counts`` (float64 and intp, one per channel) each channel's sum
    of squared residuals from the mean of its two neighbours over the (rows, channels) values'
    inner rows, and how many of those were finite (``mt_check_roughness``, csrc/mtcore.h)."""
    x = _table(values)
    rows, channels = x.shape
    _checks.output(squares, "squares", (channels,))
    _checks.output(counts, "counts", (channels,), np.uintp)
    check(lib.mt_check_roughness(c_array(x), rows, channels, channels, c_array(squares), c_array(counts, "size_t[]")),
          "mt_check_roughness")  # fmt: skip
