"""Length units: their names, the Acclaim convention, and a unit told from a character's size.

A length unit is text: a name (``m``, ``cm``, ``mm``, ``in`` and their long
forms) or a number L, the Acclaim convention of an ASF's ``:units length``:
file unit = inch / L.  CMU and HDM05 write 0.45, a unit of 2.54 / 0.45 =
5.644 cm; ``0.0254`` is the metre.

A BVH file states no unit.  :func:`size_up` tells one from the rest pose (the
skeleton as its offsets draw it) by the rule documented there; where the rule
cannot tell, :data:`ASSUMED_UNIT` is assumed and ``motiontheater info`` says so.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

METERS_PER_NAMED_UNIT = {
    "m": 1.0,
    "meter": 1.0,
    "meters": 1.0,
    "metre": 1.0,
    "metres": 1.0,
    "cm": 0.01,
    "centimeter": 0.01,
    "centimeters": 0.01,
    "centimetre": 0.01,
    "centimetres": 0.01,
    "mm": 0.001,
    "millimeter": 0.001,
    "millimeters": 0.001,
    "millimetre": 0.001,
    "millimetres": 0.001,
    "in": 0.0254,
    "inch": 0.0254,
    "inches": 0.0254,
}
SHORT_NAMES = {1.0: "m", 0.01: "cm", 0.001: "mm", 0.0254: "in"}
"""The short name of each named unit, by metres per unit."""
UNIT_HELP = "m, cm, mm, in, or a number L for the Acclaim unit inch/L (CMU and HDM05: 0.45)"

HUMAN_HEIGHT = (1.0, 2.54)
"""Metres: the sizes, low included and high not, that a detected unit must give the character.
The window is as wide as it can be with every pair of candidate units told apart: inch and cm
differ by a factor 2.54, so a height (or T-pose arm span) of 39.4 to 100 units is inches and
100 to 254 units is centimetres; 1.0 to 2.54 units is metres and 1000 to 2540 is millimetres."""
DETECTABLE = ("mm", "cm", "in", "m")
ASSUMED_UNIT = "cm"
"""The unit of a BVH file whose size tells none: centimetres, what most BVH writers of today use
(MotionBuilder, Mixamo, Rokoko, Xsens, Bandai Namco's dataset)."""
ABSURD_HEIGHT = (0.1, 25.4)
"""Metres: a stated unit that makes the character smaller or larger than this (ten times outside
:data:`HUMAN_HEIGHT`) is taken for a mistake when another unit makes it human-sized."""
SOURCES = ("stated", "default", "detected", "given", "assumed")
"""How a skeleton's length unit was chosen: stated by its file (an ASF's ``:units length``),
the Acclaim default (an ASF without one: inch), detected from its size, given by the caller
(``unit=``, ``--unit``), or assumed (:data:`ASSUMED_UNIT`, where nothing could tell)."""


def meters_per(unit: str) -> float:
    """Metres per unit of the unit text (a name, or a number L for inch / L); ValueError naming
    the text and what is accepted otherwise."""
    text = unit.strip().lower()
    if text in METERS_PER_NAMED_UNIT:
        return METERS_PER_NAMED_UNIT[text]
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value > 0):
        raise ValueError(f"unknown length unit '{unit}': give {UNIT_HELP}")
    return 0.0254 / value


def label(unit: str | None) -> str:
    """A short name of a unit for headers and reports: "m", "cm", "mm", "in", or "in/L" for
    an Acclaim number L that is none of those (None: the Acclaim default, "in")."""
    if unit is None:
        return "in"
    meters = meters_per(unit)
    return SHORT_NAMES.get(meters) or f"in/{unit.strip()}"


def named(unit: str | None) -> str | None:
    """The short name of a unit that has one (m, cm, mm, in), else None."""
    return SHORT_NAMES.get(meters_per(unit or "1"))


@dataclass(frozen=True)
class Sizing:
    """What a rest pose says about its length unit (see :func:`size_up`).

    ``extents`` are the pose's extents along x, y and z in file units; ``up``
    the standing axis ("y" or "z"); ``unit`` the unit that makes the
    character human-sized, or None; ``axis`` the axis whose extent told it.
    """

    extents: tuple[float, float, float]
    up: str
    unit: str | None
    axis: str | None

    @property
    def height(self) -> float:
        """The extent along the up axis, in file units."""
        return self.extents["xyz".index(self.up)]

    @property
    def told_by(self) -> float:
        """The extent that told the unit (file units); the height when none did."""
        return self.extents["xyz".index(self.axis or self.up)]

    def absurd(self, meters_per_unit: float) -> bool:
        """Whether a unit of ``meters_per_unit`` makes the character's largest extent absurd
        (outside :data:`ABSURD_HEIGHT`)."""
        size = max(self.extents) * meters_per_unit
        return not ABSURD_HEIGHT[0] <= size <= ABSURD_HEIGHT[1]


def human_unit(size: float) -> str | None:
    """The unit of :data:`DETECTABLE` that makes ``size`` file units a human size
    (:data:`HUMAN_HEIGHT`), or None; the windows do not overlap, so there is at most one."""
    low, high = HUMAN_HEIGHT
    return next((u for u in DETECTABLE if low <= size * METERS_PER_NAMED_UNIT[u] < high), None)


ACCLAIM_CMU = "0.45"
"""The unit of CMU's captures (inch / 0.45, 5.644 cm), which their BVH conversion keeps."""


def size_up(points: np.ndarray, *, cmu: bool = False) -> Sizing:
    """The length unit a rest pose of ``points`` (n, 3) tells, and its up axis.

    The rule: the up axis is y or z, whichever the pose spans more (BVH is
    y-up by convention, some writers are z-up; x is nobody's up), y on a tie.
    The extent along it is the standing height; the unit is the one of mm,
    cm, in, m that makes it 1.0 to 2.54 m (:data:`HUMAN_HEIGHT`).  When none
    does, the largest extent is tried the same way: a T-pose's arm span is
    about its height, and some rigs draw their rest pose along another axis
    (Rokoko's, along x).  When neither tells, ``unit`` is None.

    ``cmu``: the rig is named as CMU's BVH conversion names it (``LHipJoint``,
    ``RHipJoint``): where no unit of mm, cm, in, m makes it human, CMU's
    :data:`ACCLAIM_CMU` is tried too (its 26-unit character is 0.26 m in cm,
    0.66 m in inches, 26 m in metres, and 1.47 m in inch/0.45).

    What it cannot tell: a character whose size is not human (a child under
    1 m, a hand, an animal, a synthetic rig).  NaN points are ignored.
    """
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    finite = points[np.isfinite(points).all(axis=1)]
    with np.errstate(over="ignore"):  # a pose spanning more than the largest double: inf, no human unit
        spans = finite.max(axis=0) - finite.min(axis=0) if len(finite) else np.zeros(3)
    extents = (float(spans[0]), float(spans[1]), float(spans[2]))
    up = "z" if extents[2] > extents[1] else "y"
    largest = "xyz"[int(np.argmax(spans))]
    for axis in dict.fromkeys((up, largest)):
        unit = human_unit(extents["xyz".index(axis)])
        if unit is not None:
            return Sizing(extents, up, unit, axis)
    if cmu:
        low, high = HUMAN_HEIGHT
        for axis in dict.fromkeys((up, largest)):
            if low <= extents["xyz".index(axis)] * meters_per(ACCLAIM_CMU) < high:
                return Sizing(extents, up, ACCLAIM_CMU, axis)
    return Sizing(extents, up, None, None)


def size_up_poses(poses: np.ndarray, *, cmu: bool = False) -> Sizing:
    """What a take's poses (frames, n, 3) say, as :func:`size_up` says of one: the unit and up
    axis that most of the poses tell (the earlier pose on a tie; a unit only where at least half
    of the poses tell it), with their median extents.
    For a take whose rest pose is not a standing pose (drawn along x, or lying down)."""
    told = [size_up(pose, cmu=cmu) for pose in poses]
    if not told:
        return size_up(np.empty((0, 3)), cmu=cmu)
    votes: dict[tuple[str | None, str], int] = {}
    for sizing in told:
        votes[sizing.unit, sizing.up] = votes.get((sizing.unit, sizing.up), 0) + 1
    unit, up = max(votes, key=lambda k: (k[0] is not None, votes[k]))
    if 2 * sum(n for (u, _), n in votes.items() if u == unit) < len(told):  # a few odd poses tell nothing
        unit, up = max(votes, key=lambda k: votes[k])
    chosen = [s for s in told if (s.unit, s.up) == (unit, up)]
    x, y, z = (float(v) for v in np.median([s.extents for s in chosen], axis=0))
    return Sizing((x, y, z), up, unit, next(s.axis for s in chosen))
