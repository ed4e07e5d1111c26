"""Footplants: when each foot's heel and ball (toe base) stand on the floor.

:func:`detect_contacts` finds them from each point's height above where it
rests (see :mod:`motiontheater.feet.legs`) and its speed, the larger of the
distances to the frames before and after, per second (so that neither
difference quotient finds a planted point faster).  A frame is *close* when a
point is within ``height`` of its resting level and slower than ``speed``; a
plant is a run of close frames that holds at least one *firm* frame (within
``enter_height`` and slower than ``enter_speed``): the hysteresis that keeps a
noisy threshold from cutting a plant into pieces.  A frame within 2 cm of
rest whose central-difference speed is under 5 cm/s is always planted (a
*sure* frame).  The ends of a plant where the point has risen more than
``rise`` above its lowest frame are cut off (heel strike, push-off).  Plants
of the same point apart by at most ``gap`` seconds are merged when the point
stays slower than ``merge_speed`` in between; plants shorter than
``min_length`` seconds are dropped unless they hold a sure frame.  No plant
holds a frame faster than 0.45 m/s by the larger difference (or 5 cm/s by
the central one).  Thresholds are in
metres, m/s and seconds at the reference leg length (0.85 m hip to ankle),
multiplied by :func:`~motiontheater.feet.legs.body_scale`; frames come from the
frame rate.  The runs are found in C (:func:`mtcore.footskate.plant_masks`).

The result is a :class:`Contacts` table: one row per plant (foot, point,
first frame, last frame), which users read, edit and give back as CSV::

    # motiontheater contacts: frames 1..2751 at 120 Hz
    foot,point,first,last
    lfoot,heel,12,57
    lfoot,ball,31,80

``foot`` is the leg's ankle joint, ``point`` heel or ball, frames are the
take's frame numbers, both ends included.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from mtcore import footskate as kernels

from .._io import Source, decode, encode, output, read_source
from ..model.errors import FormatError, UnknownNameError
from .legs import Legs, body_scale

PLANT_POINTS = ("heel", "ball")
_HEADER = "# motiontheater contacts: frames {first}..{last} at {rate:g} Hz"
_COLUMNS = ["foot", "point", "first", "last"]


@dataclass(frozen=True, order=True)
class Plant:
    """One footplant: ``point`` ("heel" or "ball") of ``foot`` (the ankle joint's name) stands
    still on the floor from frame ``first`` to frame ``last`` (frame numbers, both included)."""

    foot: str
    point: str
    first: int
    last: int

    def __post_init__(self) -> None:
        if self.point not in PLANT_POINTS:
            raise ValueError(f"a plant's point is heel or ball, got {self.point!r}")
        if self.last < self.first:
            raise ValueError(f"a plant ends at or after it starts: {self.first}..{self.last}")


@dataclass(frozen=True)
class Contacts:
    """The footplants of a take of ``frames`` frames numbered from ``first_frame``.

    ``plants`` are sorted by foot, point and first frame; plants of the same
    point never overlap or touch (they are merged).  Edit by making a new
    table, e.g. ``Contacts([p for p in c.plants if p.foot != 'lfoot'], c.first_frame, c.frames)``.
    """

    plants: tuple[Plant, ...]
    first_frame: int
    frames: int
    frame_rate: float | None = None

    def __init__(self, plants: Iterable[Plant], first_frame: int, frames: int, frame_rate: float | None = None):
        merged: list[Plant] = []
        for p in sorted(plants, key=lambda p: (p.foot, p.point, p.first, p.last)):
            if not first_frame <= p.first <= p.last <= first_frame + frames - 1:
                raise ValueError(
                    f"plant {p.foot} {p.point} {p.first}..{p.last} is outside the take's frames "
                    f"{first_frame}..{first_frame + frames - 1}"
                )
            last = merged[-1] if merged else None
            if last and (last.foot, last.point) == (p.foot, p.point) and p.first <= last.last + 1:
                merged[-1] = Plant(p.foot, p.point, last.first, max(last.last, p.last))
            else:
                merged.append(p)
        object.__setattr__(self, "plants", tuple(merged))
        object.__setattr__(self, "first_frame", int(first_frame))
        object.__setattr__(self, "frames", int(frames))
        object.__setattr__(self, "frame_rate", frame_rate)

    def __len__(self) -> int:
        return len(self.plants)

    def of(self, foot: str, point: str | None = None) -> tuple[Plant, ...]:
        """The plants of a foot (its ankle joint's name), of one point or both."""
        return tuple(p for p in self.plants if p.foot == foot and (point is None or p.point == point))

    def check_take(self, first_frame: int, frames: int) -> None:
        """Raise ValueError unless the table is of a take of ``frames`` frames from ``first_frame``."""
        if (self.first_frame, self.frames) != (first_frame, frames):
            raise ValueError(
                f"the contacts are for frames {self.first_frame}..{self.first_frame + self.frames - 1}, the take "
                f"has frames {first_frame}..{first_frame + frames - 1}: they are for another take"
            )

    def marks(self, legs: Legs) -> list[tuple[str, int, np.ndarray]]:
        """Where each foot's plants are shown: (label such as "lfoot heel", the index in
        :meth:`Motion.positions` of the point marked, flags (frames,) bool), heel then ball of
        each leg.  The ball is marked at the ball; the heel at the heel joint where the skeleton
        has one, else (a derived heel) at the ankle above it.  Raises UnknownNameError as
        :meth:`masks`."""
        masks = self.masks(legs)
        out = []
        for i, foot in enumerate(legs.feet):
            heel = int(legs.points[i, 5]) if legs.points[i, 5] >= 0 else int(legs.points[i, 2])
            for k, (point, where) in enumerate(zip(PLANT_POINTS, (heel, int(legs.points[i, 3])))):
                out.append((f"{foot} {point}", where, masks[i, :, k]))
        return out

    def masks(self, legs: Legs) -> np.ndarray:
        """(legs, frames, 2) bool: whether each leg's heel and ball are planted at each frame.
        Raises UnknownNameError for a plant of a foot that is not one of the legs'."""
        out = np.zeros((len(legs), self.frames, 2), bool)
        feet = {foot: i for i, foot in enumerate(legs.feet)}
        for p in self.plants:
            if p.foot not in feet:
                raise UnknownNameError(
                    f"the contacts name foot '{p.foot}', which is not a foot of this skeleton "
                    f"({', '.join(legs.feet)}): are they for another take?"
                )
            out[
                feet[p.foot], p.first - self.first_frame : p.last - self.first_frame + 1, PLANT_POINTS.index(p.point)
            ] = True
        return out

    @classmethod
    def from_masks(cls, masks: np.ndarray, legs: Legs, first_frame: int, frame_rate: float | None = None) -> Contacts:
        """The table of masks (legs, frames, 2) (heel, ball)."""
        plants = []
        frames = masks.shape[1]
        for i, foot in enumerate(legs.feet):
            for k, point in enumerate(PLANT_POINTS):
                starts, ends = runs(masks[i, :, k])
                plants += [
                    Plant(foot, point, first_frame + int(s), first_frame + int(e) - 1) for s, e in zip(starts, ends)
                ]
        return cls(plants, first_frame, frames, frame_rate)

    def to_csv(self, target: Source) -> None:
        """Write the table as CSV (see the module docstring), atomically to a path."""
        text = io.StringIO()
        last = self.first_frame + self.frames - 1
        text.write(_HEADER.format(first=self.first_frame, last=last, rate=self.frame_rate or 0) + "\n")
        writer = csv.writer(text, lineterminator="\n")
        writer.writerow(_COLUMNS)
        for p in self.plants:
            writer.writerow([p.foot, p.point, p.first, p.last])
        with output(target) as f:
            f.write(encode(text.getvalue()))

    @classmethod
    def read_csv(cls, source: Source, *, first_frame: int, frames: int) -> Contacts:
        """Read a table written by :meth:`to_csv` (or by hand) for a take of ``frames`` frames
        from ``first_frame``.  Comment lines start with '#'; a header comment of another
        frame range, an unknown column, a bad number or a plant outside the take raises
        FormatError naming the file and line."""
        data, name = read_source(source)
        plants = []
        header_seen = False
        for number, line in enumerate(decode(data).splitlines(), start=1):
            stripped = line.strip()
            try:
                if not stripped:
                    continue
                if stripped.startswith("#"):
                    _check_range(stripped, first_frame, frames)
                    continue
                row = [cell.strip() for cell in next(csv.reader([stripped]))]
                if not header_seen:
                    if [c.lower() for c in row] != _COLUMNS:
                        raise FormatError(f"expected the header '{','.join(_COLUMNS)}', found '{stripped[:60]}'")
                    header_seen = True
                    continue
                if len(row) != 4:
                    raise FormatError(f"expected 4 cells (foot,point,first,last), found {len(row)}")
                foot, point, first, last = row
                try:
                    start, end = int(first), int(last)
                except ValueError:
                    raise FormatError(f"expected whole frame numbers, found '{first}' and '{last}'") from None
                if point.lower() not in PLANT_POINTS:
                    raise FormatError(f"the point must be heel or ball, found '{point}'")
                if not first_frame <= start <= end <= first_frame + frames - 1:
                    raise FormatError(
                        f"plant {start}..{end} is not within the take's frames "
                        f"{first_frame}..{first_frame + frames - 1}: is this table for another take?"
                    )
                plants.append(Plant(foot, point.lower(), start, end))
            except FormatError as e:
                raise FormatError(e.reason, number, name) from None
        if not header_seen:
            raise FormatError(f"no header line '{','.join(_COLUMNS)}'", None, name)
        return cls(plants, first_frame, frames)


def _check_range(comment: str, first_frame: int, frames: int) -> None:
    words = comment.lstrip("#").split()
    if "frames" not in words or "contacts:" not in words:
        return
    span = words[words.index("frames") + 1]
    try:
        a, b = (int(x) for x in span.split(".."))
    except ValueError:
        return
    if (a, b) != (first_frame, first_frame + frames - 1):
        raise FormatError(
            f"these contacts are for frames {a}..{b}, and the take has frames "
            f"{first_frame}..{first_frame + frames - 1}: they are for another take"
        )


def runs(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Starts and ends (exclusive) of the runs of True in a 1-d mask."""
    padded = np.zeros(len(mask) + 2, bool)
    padded[1:-1] = mask
    edges = np.flatnonzero(padded[1:] != padded[:-1])  # where runs start and end, in turn
    return edges[::2], edges[1::2]


def run_peaks(mask: np.ndarray, values: np.ndarray) -> list[tuple[int, int, int, float]]:
    """The runs of True in each row of a 2-d mask, row by row: (row, start, end (exclusive), the
    largest of ``values`` (the mask's shape) over the run), every row's at once."""
    if not mask.any():  # as nearly every take's knees and elbows
        return []
    rows, frames = mask.shape
    padded = np.zeros((rows, frames + 1), bool)  # a False between rows parts their runs
    padded[:, :frames] = mask
    starts, ends = runs(padded.ravel())
    if not len(starts):
        return []
    row = starts // (frames + 1)
    first = starts - row  # into values, row by row without the padding
    bounds = np.stack([first, first + ends - starts], axis=1).ravel()
    flat = np.ascontiguousarray(values).ravel()
    peaks = np.maximum.reduceat(flat, bounds[:-1] if bounds[-1] == len(flat) else bounds)[::2]
    return list(zip(row.tolist(), (starts % (frames + 1)).tolist(), (ends % (frames + 1)).tolist(), peaks.tolist()))


@dataclass(frozen=True)
class Thresholds:
    """Footplant detection thresholds at the reference leg length (see the module docstring)."""

    height: float = 0.03  # m: close to rest
    speed: float = 0.40  # m/s (at most 0.45 once scaled: a plant never holds a point at 0.5 m/s)
    enter_height: float = 0.02  # m: firmly at rest
    enter_speed: float = 0.35  # m/s
    rise: float = 0.01  # m: a plant's ends higher than this above its lowest frame are cut off
    gap: float = 0.10  # s: plants this close merge when the point stays slower than merge_speed between
    merge_speed: float = 0.40  # m/s, not scaled: what a plant must never hold is 0.5 m/s
    min_length: float = 0.05  # s

    def __post_init__(self) -> None:
        for name in ("height", "speed", "enter_height", "enter_speed", "rise", "gap", "merge_speed", "min_length"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and value >= 0 and np.isfinite(value)):
                raise ValueError(f"threshold {name} must be a number >= 0, got {value!r}")
        if self.enter_height > self.height or self.enter_speed > self.speed:
            raise ValueError("the enter thresholds must not exceed height and speed (hysteresis)")


DEFAULT = Thresholds()
SURE_HEIGHT, SURE_SPEED = 0.02, 0.05  # m, m/s: within these a point is planted, whatever else
FASTEST = 0.45  # m/s: the speed threshold once scaled never exceeds this


def detect_masks(
    heights: np.ndarray,
    speed: np.ndarray,
    central: np.ndarray,
    frame_rate: float,
    meters_per_unit: float,
    scale: float,
    thresholds: Thresholds = DEFAULT,
) -> np.ndarray:
    """Footplant masks (..., frames) from heights (..., frames) in file units above rest and
    speeds (..., frames) in file units per second: ``speed`` the larger of the forward and backward
    differences, ``central`` the central difference (:func:`~motiontheater.feet.legs.speeds`); see the
    module docstring."""
    th = thresholds
    unit = scale / meters_per_unit
    fastest = FASTEST / meters_per_unit
    limits = kernels.PlantThresholds(
        sure_height=SURE_HEIGHT / meters_per_unit,
        sure_speed=SURE_SPEED / meters_per_unit,
        height=th.height * unit,
        speed=min(th.speed * unit, fastest),
        firm_height=th.enter_height * unit,
        firm_speed=min(th.enter_speed * unit, fastest),
        merge_speed=th.merge_speed / meters_per_unit,
        rise=th.rise * unit,
        gap=round(th.gap * frame_rate),
        shortest=round(th.min_length * frame_rate),
    )
    n = heights.shape[-1]

    def rows(a: np.ndarray) -> np.ndarray:
        return np.reshape(a, (-1, n))

    return kernels.plant_masks(rows(heights), rows(speed), rows(central), limits).reshape(heights.shape)


def _bounds(starts: np.ndarray, ends: np.ndarray, n: int) -> np.ndarray:
    """Indices for ufunc.reduceat over runs [start, end) of n items: every run's start and end in
    turn (the even pieces are the runs), without an end at n, where reduceat stops anyway."""
    bounds = np.empty(2 * len(starts), np.int64)
    bounds[0::2], bounds[1::2] = starts, ends
    return bounds[:-1] if len(bounds) and bounds[-1] == n else bounds


def detect_contacts(
    arrays,
    ground,
    frame_rate: float,
    meters_per_unit: float,
    first_frame: int = 1,
    thresholds: Thresholds = DEFAULT,
) -> Contacts:
    """The footplants of a take's legs (:class:`~motiontheater.feet.legs.LegArrays`) on its ground."""
    heights = ground.above(arrays.points[:, :, 2:4])[:, :, ::-1]  # ball, heel: heel, ball
    heights -= ground.clearance[:, None, :2]
    heights = heights.transpose(0, 2, 1)  # (legs, 2, frames)
    speed, central = kernels.point_speeds(arrays.points, [3, 2], frame_rate, central=True)
    scale = body_scale(arrays.legs, meters_per_unit)
    masks = detect_masks(heights, speed, central, frame_rate, meters_per_unit, scale, thresholds).transpose(0, 2, 1)
    return Contacts.from_masks(masks, arrays.legs, first_frame, frame_rate)


def plant_targets(masks: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Targets (legs, frames, 2, 3) for heel and ball: at each planted frame, the point's mean
    position over its plant (NaN elsewhere).  ``points`` (legs, frames, 5, 3) as leg_points."""
    out = np.full(masks.shape + (3,), np.nan)
    frames = masks.shape[1]
    for i in range(masks.shape[0]):
        for k, column in enumerate((3, 2)):
            starts, ends = runs(masks[i, :, k])
            if not len(starts):
                continue
            bounds = _bounds(starts, ends, frames)
            means = np.add.reduceat(points[i, :, column], bounds, axis=0)[::2] / (ends - starts)[:, None]
            out[i, masks[i, :, k], k] = np.repeat(means, ends - starts, axis=0)  # planted frames, in order
    return out
