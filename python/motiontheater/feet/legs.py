"""Legs, up axis and floor of a take: what footplant detection, footskate cleanup and their metrics stand on.

A leg is named by the joints that turn its segments: ``hip`` turns the thigh,
``knee`` the shin, ``ankle`` the foot and ``toe`` (optional) the toes.  In
ASF/AMC these are bones (CMU and HDM05: ``lfemur``, ``ltibia``, ``lfoot``,
``ltoes``); in BVH the joints at the hip, knee, ankle and ball
(``LeftUpLeg``, ``LeftLeg``, ``LeftFoot``, ``LeftToeBase``).  :func:`find_legs`
finds them from the names and the hierarchy: a joint whose name is a side
(``l``, ``left``, ``r``, ``right``, as prefix or suffix, any separator, any
namespace such as ``mixamorig:``) and a foot word (``foot``, ``ankle``) is
an ankle; its parent is the knee and the knee's parent the hip; its child
named ``toe``/``toes``/``toebase``/``ball`` (or its only child that turns)
is the toe.  An ASF bone named after the point it ends at (a skeleton
converted from BVH: bone ``LeftFoot`` runs from the knee to the ankle) is
told apart by its length: a "foot" as long as its parent is a shin.

The points of a leg are the hip, knee, ankle, ball (toe base: the foot
segment's far end) and the toe tip (the toe segment's far end, when there is
one).  The heel is a joint named ``heel`` below the ankle when the skeleton
has one; otherwise it is derived: the point below the ankle, along the rest
pose's downward axis (the coordinate axis nearest to hip -> ankle in the rest
pose), at the depth of the ball, carried rigidly with the foot.  In a rest
pose standing on a flat foot that is where the heel touches the floor when the
ball does.  A rig whose rest pose does not stand (its foot more than 45
degrees from horizontal there, e.g. pointing down the leg) takes it from the
take instead: the point below the ankle, along the world's up axis seen from
the foot, at the ball's depth, in the frames where ankle and ball both rest
low and still (flat stance: within 0.2 m/s and 2 cm of their lowest tenth, or twice or four
times that in a take with fewer than three such frames); a take without such frames raises
ValueError.

The floor is a plane: the level at which the lowest contact point rests,
tilted as the resting contact points say (capture volumes are often
calibrated a degree or two off level: CMU 07_05 climbs 6 cm over 4 m).  Each
contact point (heel, ball and toe tip of each foot) rests at its own
clearance above it: joint centres are inside the foot, not on its sole.  A
point's *height* is its distance above the floor minus its clearance: 0 when
it rests on the floor.  All lengths here are in the take's file units; the
thresholds of detection are in metres and m/s, converted with the skeleton's
``meters_per_unit`` and scaled by the leg length (see :func:`body_scale`).
"""

from __future__ import annotations

import itertools
import re
from collections.abc import Sequence
from dataclasses import InitVar, dataclass
from functools import cached_property

import numpy as np

from mtcore import footskate as kernels
from mtcore.kinematics import Kinematics, forward_kinematics

from ..model.errors import UnknownNameError
from ..model.motion import Motion
from ..model.skeleton import ROTATIONS, Skeleton

SIDES = ("left", "right")
CONTACT_POINTS = ("heel", "ball", "tip")
REFERENCE_LEG = 0.85
"""Hip-to-ankle length (m) of the adult the detection thresholds are stated for."""

_SIDE_WORDS = {"left": ("left", "l"), "right": ("right", "r")}
_PARTS = {
    "ankle": ("foot", "ankle"),
    "toe": ("toebase", "toes", "toe", "ball"),
    "heel": ("heel",),
}
_AXES = {"x": 0, "y": 1, "z": 2}


@dataclass(frozen=True)
class Leg:
    """The joints turning a leg's thigh, shin, foot and toes (``toe`` may be None)."""

    side: str
    hip: str
    knee: str
    ankle: str
    toe: str | None = None

    @property
    def joints(self) -> tuple[str, ...]:
        """The leg's joints, hip to toe."""
        return (self.hip, self.knee, self.ankle) + ((self.toe,) if self.toe else ())


@dataclass(frozen=True, eq=False)
class Legs:
    """The legs of a skeleton, resolved to indices and rest geometry.

    ``rotators`` (legs, 4): indices in ``skeleton.joint_names`` of the hip,
    knee, ankle and toe joints (-1: no toe).  ``points`` (legs, 6): indices in
    :meth:`Motion.positions` of the hip, knee, ankle, ball, toe tip and heel
    points (-1: no tip; no heel joint, the heel is derived).  ``segments``
    (legs, 5, 3), in file units, each in the frame of the joint that turns
    it (the rest pose's axes): hip -> knee (thigh), knee -> ankle (shin),
    ankle -> ball and ankle -> heel (foot), ball -> tip (toes; zero without);
    NaN heels are derived from a take by :func:`leg_arrays`.
    ``parents`` (legs,): the index of the hip joint's parent.
    """

    skeleton: Skeleton
    legs: tuple[Leg, ...]
    rotators: np.ndarray
    points: np.ndarray
    segments: np.ndarray
    parents: np.ndarray

    def __len__(self) -> int:
        return len(self.legs)

    @property
    def feet(self) -> tuple[str, ...]:
        """Each leg's ankle joint: the name a contacts table gives its foot."""
        return tuple(leg.ankle for leg in self.legs)

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Every joint the legs turn."""
        return tuple(name for leg in self.legs for name in leg.joints)

    @property
    def heels_missing(self) -> np.ndarray:
        """Which legs' heels the rest pose does not give (NaN segments: derived from a take)."""
        return np.isnan(self.segments[:, 3]).any(axis=1)

    @cached_property
    def _length(self) -> float:
        return float(np.mean(np.linalg.norm(self.segments[:, :2], axis=-1).sum(axis=1)))

    def leg_length(self) -> float:
        """Mean over the legs of thigh plus shin length (hip to ankle at full extension), file units."""
        return self._length


_SEPARATORS = re.compile(r"[\s_.\-]")


def _normal(name: str) -> str:
    """A joint name without namespace, case or separators: 'mixamorig:Left_Up-Leg' -> 'leftupleg'."""
    return _SEPARATORS.sub("", name.rsplit(":", 1)[-1]).lower()


# the names of a side's part: the side word before or after the part's ("lfoot", "footleft")
_SIDE_PART_NAMES = {
    (side, part): frozenset(w for s in _SIDE_WORDS[side] for p in words for w in (s + p, p + s))
    for side in SIDES
    for part, words in _PARTS.items()
}


def _side_part(name: str, side: str, part: str) -> bool:
    return _normal(name) in _SIDE_PART_NAMES[side, part]


def _turns(skeleton: Skeleton, name: str) -> bool:
    return name != "root" and any(d in ROTATIONS for d in skeleton.dofs(name))


def find_legs(skeleton: Skeleton, names: Sequence[str] | None = None) -> tuple[Leg, ...]:
    """The left and right legs of a skeleton, by names and hierarchy (see the module docstring).

    ``names`` overrides: hip, knee, ankle[, toe] of the left leg, then the
    same of the right leg (6 or 8 names, e.g. ``lfemur,ltibia,lfoot,ltoes,
    rfemur,rtibia,rfoot,rtoes``).  Raises ValueError naming what is missing
    when no leg is recognised, UnknownNameError for a name not in the skeleton.
    """
    if names is not None:
        names = tuple(names)
        if len(names) not in (6, 8):
            raise ValueError(
                f"legs takes hip,knee,ankle[,toe] of the left leg then of the right leg (6 or 8 names), "
                f"got {len(names)}: {','.join(names)}"
            )
        per = len(names) // 2
        legs = []
        for i, side in enumerate(SIDES):
            chain = names[i * per : (i + 1) * per]
            for name in chain:
                skeleton.bone(name)  # UnknownNameError names it
            legs.append(Leg(side, *chain))
        return tuple(legs)
    return tuple(_find_leg(skeleton, side) for side in SIDES)


def _find_leg(skeleton: Skeleton, side: str) -> Leg:
    named = [b.name for b in skeleton.bones if not b.end_site and _side_part(b.name, side, "ankle")]
    below: list[str | None] = list(named)
    if skeleton.convention != "bvh":
        # an ASF bone named after the point it ends at ("LeftFoot": knee to ankle) is a shin: its foot is below
        below = [_below_if_shin(skeleton, a) for a in named]
    ankles = [a for a in below if a is not None and _turns(skeleton, a)]
    if not ankles:
        why = (
            f"'{named[0]}' is as long as a shin and has no foot below it"
            if named
            else f"no joint with rotation channels is named like a {side} foot or ankle "
            f"({side[0]}foot, {side.capitalize()}Foot, {side}_ankle, ...)"
        )
        raise ValueError(
            f"no {side} leg in skeleton '{skeleton.name or '(unnamed)'}': {why}; name the legs with "
            "legs=hip,knee,ankle[,toe] of the left leg then of the right leg (--legs)"
        )
    ankle = ankles[0]
    knee = skeleton.parent(ankle)
    hip = skeleton.parent(knee) if knee != "root" else "root"
    if hip == "root" or not _turns(skeleton, knee) or not _turns(skeleton, hip):
        raise ValueError(
            f"the {side} foot '{ankle}' does not hang from a knee and a hip that turn "
            f"(its parent is '{knee}'{'' if knee == 'root' else f', then {hip!r}'}); give the legs (--legs)"
        )
    children = [c for c in skeleton.children(ankle) if _turns(skeleton, c)]
    toes = [c for c in children if any(p in _normal(c) for p in _PARTS["toe"])] or (
        children if len(children) == 1 else []
    )
    return Leg(side, hip, knee, ankle, toes[0] if toes else None)


def _below_if_shin(skeleton: Skeleton, name: str) -> str | None:
    bone, parent = skeleton.bone(name), skeleton.parent(name)
    if parent == "root" or bone.length <= 0.6 * skeleton.bone(parent).length:
        return name
    below = [c for c in skeleton.children(name) if _turns(skeleton, c)]
    return below[0] if len(below) == 1 else None


def resolve_legs(skeleton: Skeleton, legs: Sequence[Leg] | Sequence[str] | None = None) -> Legs:
    """The legs of a skeleton with their indices and rest geometry (:class:`Legs`).

    ``legs``: None (find them), names as for :func:`find_legs`, or Leg objects.
    Raises ValueError when a chain is not a chain (each joint the child of the
    one before), a hip or knee does not turn, or a leg joint has translation
    channels; UnknownNameError for a joint the skeleton does not have.
    """
    if legs is None or (legs and isinstance(next(iter(legs)), str)):
        names = None if legs is None else tuple(legs)  # every take of a skeleton asks: worked out once
        return skeleton.derived(("legs", names), lambda: _resolve(skeleton, find_legs(skeleton, names)))  # type: ignore[arg-type]
    return _resolve(skeleton, tuple(legs))  # type: ignore[arg-type]


def _resolve(skeleton: Skeleton, found: tuple[Leg, ...]) -> Legs:
    index = {n: i for i, n in enumerate(skeleton.joint_names)}
    rest = skeleton.rest_positions()
    for leg in found:
        _check_chain(skeleton, leg)
    down = _rest_down(rest, found, index, skeleton)
    rotators, points, segments, parents = [], [], [], []
    for leg in found:
        hip, knee, ankle, ball, tip, heel = _points_of(skeleton, index, leg)
        foot = rest[ball] - rest[ankle]
        if heel >= 0:
            heel_vector = rest[heel] - rest[ankle]
        else:
            drop = float(foot @ down)
            # a rest pose that does not stand on its foot: the heel comes from the take (leg_arrays)
            standing = 0 <= drop <= np.sqrt(0.5) * np.linalg.norm(foot)
            heel_vector = down * drop if standing else np.full(3, np.nan)
        rotators.append([index[leg.hip], index[leg.knee], index[leg.ankle], index[leg.toe] if leg.toe else -1])
        points.append([hip, knee, ankle, ball, tip, heel])
        segments.append(
            [
                rest[knee] - rest[hip],
                rest[ankle] - rest[knee],
                foot,
                heel_vector,
                rest[tip] - rest[ball] if tip >= 0 else np.zeros(3),
            ]
        )
        parents.append(index[skeleton.parent(leg.hip)])
    return Legs(
        skeleton,
        found,
        np.array(rotators, np.int64),
        np.array(points, np.int64),
        np.array(segments, float),
        np.array(parents, np.int64),
    )


def _check_chain(skeleton: Skeleton, leg: Leg) -> None:
    for name in leg.joints:
        if name == "root":
            raise UnknownNameError(f"the root cannot be a leg joint ({leg.side} leg)")
        skeleton.bone(name)  # UnknownNameError names it
    chain = leg.joints
    for upper, lower in itertools.pairwise(chain):
        if skeleton.parent(lower) != upper:
            raise ValueError(f"{leg.side} leg: '{lower}' is not a child of '{upper}' (legs must be chains)")
    for name, what in ((leg.hip, "hip"), (leg.knee, "knee")):
        if not _turns(skeleton, name):
            raise ValueError(f"{leg.side} leg: the {what} '{name}' has no rotation channels")
    for name in chain[1:]:  # a hip that shifts moves where the leg starts, not how long its bones are
        extra = [d for d in skeleton.dofs(name) if d not in ROTATIONS]
        if extra:
            raise ValueError(
                f"{leg.side} leg: '{name}' has translation or stretch channels ({', '.join(extra)}) that move: "
                "footskate cleanup turns leg joints only"
            )


def _points_of(skeleton: Skeleton, index: dict[str, int], leg: Leg) -> tuple[int, int, int, int, int, int]:
    """Indices in Motion.positions() of a leg's hip, knee, ankle, ball, toe tip and heel (-1: none):
    in ASF a bone's end point, in BVH a joint's own position."""
    bvh = skeleton.convention == "bvh"

    def start(name: str) -> int:  # where the segment a joint turns begins
        return index[name] if bvh else index[skeleton.parent(name)]

    def end(name: str) -> int:  # where it ends
        if not bvh:
            return index[name]
        kids = skeleton.children(name)
        following = [k for k in kids if k in leg.joints] or [k for k in kids if not _is_heel(k)]
        return index[following[0]] if following else -1

    ball = start(leg.toe) if leg.toe else end(leg.ankle)
    if ball < 0:
        raise ValueError(f"{leg.side} leg: the foot '{leg.ankle}' has no end point (a toe or End Site) for a ball")
    heels = [c for c in skeleton.children(leg.ankle) if _is_heel(c)]
    heel = index[heels[0]] if heels else -1  # ASF: the heel bone's end; BVH: the heel joint
    return start(leg.hip), start(leg.knee), start(leg.ankle), ball, end(leg.toe) if leg.toe else -1, heel


def _is_heel(name: str) -> bool:
    return "heel" in _normal(name)


def _rest_down(rest: np.ndarray, legs: Sequence[Leg], index: dict[str, int], skeleton: Skeleton) -> np.ndarray:
    """The signed coordinate axis nearest to hip -> ankle in the rest pose, averaged over the legs."""
    bvh = skeleton.convention == "bvh"
    total = np.zeros(3)
    for leg in legs:
        hip = index[leg.hip] if bvh else index[skeleton.parent(leg.hip)]
        ankle = index[leg.ankle] if bvh else index[skeleton.parent(leg.ankle)]
        v = rest[ankle] - rest[hip]
        total += v / (np.linalg.norm(v) or 1.0)
    return signed_axis_vector(total)


def along(p: np.ndarray, v: np.ndarray) -> np.ndarray:
    """p . v for points (..., 3) and a vector v, the dot product written out (matmul with a vector
    takes a slow path for stacked points), summed in place: on an hour of frames a temporary per
    term is as much fresh memory again."""
    p = np.asarray(p)
    if p.ndim < 2:  # one point: a number
        return p[0] * v[0] + p[1] * v[1] + p[2] * v[2]
    out = np.multiply(p[..., 0], v[0])
    term = np.multiply(p[..., 1], v[1])
    out += term
    out += np.multiply(p[..., 2], v[2], out=term)
    return out


def signed_axis_vector(v: np.ndarray) -> np.ndarray:
    """The unit coordinate axis (with sign) nearest to the direction of v."""
    axis = int(np.argmax(np.abs(v)))
    out = np.zeros(3)
    out[axis] = 1.0 if v[axis] >= 0 else -1.0
    return out


def parse_up(up: str) -> np.ndarray:
    """'y', '+z', '-y' ... as a unit vector."""
    text = up.strip().lower()
    sign = -1.0 if text.startswith("-") else 1.0
    letter = text.lstrip("+-")
    if letter not in _AXES:
        raise ValueError(f"up must be an axis x, y or z (optionally signed, e.g. -z), got {up!r}")
    out = np.zeros(3)
    out[_AXES[letter]] = sign
    return out


def axis_name(v: np.ndarray) -> str:
    """The name of the signed coordinate axis nearest to v: "y", "-z"..."""
    axis = int(np.argmax(np.abs(v)))
    return ("-" if v[axis] < 0 else "") + "xyz"[axis]


def body_scale(legs: Legs, meters_per_unit: float) -> float:
    """How much larger than the reference adult (hip to ankle 0.85 m) the legs are, kept within
    0.6 .. 1.2: detection thresholds in metres and m/s are multiplied by it."""
    return min(max(float(legs.leg_length() * meters_per_unit / REFERENCE_LEG), 0.6), 1.2)  # np.clip: microseconds


@dataclass(frozen=True, eq=False)
class LegArrays:
    """A motion's legs as arrays for the kernels of :mod:`mtcore.footskate` (see there for shapes):
    ``points`` (legs, frames, 5, 3), knee, ankle, ball, heel and toe tip, and ``hips`` (legs,
    frames, 3).  What the cleanup needs besides is worked out from ``motion`` when first read
    (the check reads the points alone), where the maker did not have it (``given``): the legs'
    ``chains``, the ``angles`` (radians) of the channels ``columns`` (legs, 4, 3) of
    ``motion.values`` (-1 unused), in the order they apply, and the world rotations of the hips'
    ``parents`` (legs, frames, 3, 3)."""

    legs: Legs
    motion: Motion
    hips: np.ndarray
    points: np.ndarray
    given: InitVar[dict[str, object] | None] = None

    def __post_init__(self, given: dict[str, object] | None) -> None:
        for name, value in (given or {}).items():  # what the properties below would work out again
            object.__setattr__(self, name, value)

    @property
    def angle_scale(self) -> float:
        """Radians per unit of the motion's angles."""
        return self.motion.skeleton.tree.angle_scale

    @cached_property
    def chains(self) -> tuple:
        """Each leg's :class:`mtcore.footskate.LegChain`."""
        return _chains(self.motion.skeleton, self.legs)

    @cached_property
    def columns(self) -> np.ndarray:
        """The columns of the legs' rotation channels (legs, 4, 3; -1 unused)."""
        return _leg_channels(self.motion.skeleton, self.legs)[0]

    @cached_property
    def angles(self) -> np.ndarray:
        """The legs' rotation channels over the frames in radians (legs, frames, 4, 3)."""
        return _leg_angles(self.motion, self.legs)

    @cached_property
    def parents(self) -> np.ndarray:
        """The world rotations of the hips' parents (legs, frames, 3, 3)."""
        return _upper_kinematics(self.motion.values, self.motion.skeleton, self.legs)[1]


_CHUNK = 16384  # frames of forward kinematics at a time: the joints' rotations stay in cache, not in memory


def _upper_kinematics(
    values: np.ndarray, skeleton: Skeleton, legs: Legs, kinematics: Kinematics | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Hip points (legs, frames, 3) and the world rotations of the hip joints' parents (legs,
    frames, 3, 3): from ``kinematics`` where given, else by forward kinematics of the joints above
    the legs only, in chunks of frames."""
    if kinematics is not None:
        hips = np.ascontiguousarray(kinematics.positions[:, legs.points[:, 0]].transpose(1, 0, 2))
        turns = kinematics.world[:, kinematics.rows(legs.parents)]
        return hips, np.ascontiguousarray(turns.transpose(1, 0, 2, 3))
    joints = (*map(int, legs.parents), *map(int, legs.points[:, 0]))
    upper, where = skeleton.derived(("pruned tree", joints), lambda: skeleton.tree.pruned(list(joints)))
    hip_rows = where[legs.points[:, 0]]
    parent_rows = where[legs.parents]
    frames = len(values)
    hips = np.empty((len(legs), frames, 3))
    parents = np.empty((len(legs), frames, 3, 3))
    for start in range(0, frames, _CHUNK):
        stop = min(start + _CHUNK, frames)
        positions, world, _ = forward_kinematics(values[start:stop], upper, world=True, workers=1)
        assert world is not None
        hips[:, start:stop] = positions[:, hip_rows].transpose(1, 0, 2)
        parents[:, start:stop] = world[:, parent_rows].transpose(1, 0, 2, 3)
    return hips, parents


def _leg_channels(skeleton: Skeleton, legs: Legs) -> tuple[np.ndarray, np.ndarray, list[np.ndarray]]:
    """The legs' rotation channels: their columns (legs, 4, 3) in the order they apply (-1
    unused), their axes (0 x, 1 y, 2 z; -1 unused) and each leg's joints' axis frames (4, 3, 3);
    worked out once per skeleton."""

    def made() -> tuple[np.ndarray, np.ndarray, list[np.ndarray]]:
        tree, n = skeleton.tree, len(legs)
        columns = np.full((n, 4, 3), -1, np.int64)
        axes = np.full((n, 4, 3), -1, np.intc)
        for i in range(n):
            for r, j in enumerate(legs.rotators[i]):
                if j < 0:
                    continue
                a, b = tree.dof_start[j], tree.dof_start[j + 1]
                rot = [(k, c) for k, c in zip(tree.dof_kind[a:b], tree.dof_column[a:b]) if k <= 2]
                for m, (k, c) in enumerate(rot):
                    axes[i, r, m], columns[i, r, m] = k, c
        frames_axis = [np.stack([tree.axis[j] if j >= 0 else np.eye(3) for j in legs.rotators[i]]) for i in range(n)]
        return columns, axes, frames_axis

    return skeleton.derived(("leg channels", legs.rotators.tobytes()), made)


def _chains(skeleton: Skeleton, legs: Legs, segments: np.ndarray | None = None) -> tuple:
    """The legs' chains for the kernels, of ``segments`` (default the legs' own, the rest pose's:
    worked out once per skeleton)."""
    _, axes, frames_axis = _leg_channels(skeleton, legs)

    def made(segments: np.ndarray) -> tuple:
        return tuple(
            kernels.LegChain(axis=frames_axis[i], axes=axes[i], segments=segments[i]) for i in range(len(legs))
        )

    if segments is not None:
        return made(segments)
    return skeleton.derived(("leg chains", legs.segments.tobytes()), lambda: made(legs.segments))


def _leg_angles(motion: Motion, legs: Legs) -> np.ndarray:
    """The legs' rotation channels over the frames, in radians (legs, frames, 4, 3; 0 unused)."""
    columns = _leg_channels(motion.skeleton, legs)[0]
    used = columns >= 0
    gathered = np.take(motion.values, np.where(used, columns, 0).ravel(), axis=1)  # (frames, legs * 4 * 3)
    gathered *= motion.skeleton.tree.angle_scale
    gathered[:, ~used.ravel()] = 0.0
    return np.ascontiguousarray(gathered.reshape(len(gathered), len(legs), 4, 3).transpose(1, 0, 2, 3))


def leg_arrays(
    motion: Motion,
    legs: Legs,
    *,
    up: str | np.ndarray | None = None,
    meters_per_unit: float | None = None,
    kinematics: Kinematics | None = None,
) -> LegArrays:
    """The legs of a motion as arrays: their points from ``kinematics`` (the motion's, where the
    caller has them with the feet's world rotations: :func:`mtcore.footskate.placed_legs`), else
    by forward kinematics of the joints above the legs (in C) and ``leg_points`` of the legs'
    angles.  Heels the rest pose could not give are derived from this take (see the module
    docstring), along ``up`` (:func:`choose_up`), with thresholds in metres by
    ``meters_per_unit`` (default the skeleton's)."""
    skeleton = motion.skeleton
    missing = legs.heels_missing
    placed = None if missing.any() or kinematics is None else _placed(legs, kinematics)
    if placed is not None:
        return LegArrays(legs, motion, *placed)
    hips, parents = _upper_kinematics(motion.values, skeleton, legs, kinematics)
    angles = _leg_angles(motion, legs)
    columns = _leg_channels(skeleton, legs)[0]
    if missing.any():
        segments = legs.segments.copy()
        segments[missing, 3] = 0.0
        chains = _chains(skeleton, legs, segments)
        points, feet = kernels.leg_points(chains, hips, parents, angles, feet=True)
        partial = LegArrays(legs, motion, hips, points)
        mpu = skeleton.meters_per_unit if meters_per_unit is None else meters_per_unit
        direction = choose_up(partial, up)
        for i in map(int, np.flatnonzero(missing)):
            segments[i, 3] = _heel_from_take(points[i], feet[i], direction, motion.frame_rate, mpu, legs, i)
        legs = Legs(legs.skeleton, legs.legs, legs.rotators, legs.points, segments, legs.parents)
        chains = _chains(skeleton, legs, legs.segments)  # the take's own heels: not kept with the skeleton
    else:
        chains = _chains(skeleton, legs)
    points = kernels.leg_points(chains, hips, parents, angles)
    return LegArrays(legs, motion, hips, points, dict(chains=chains, parents=parents, angles=angles, columns=columns))


def _placed(legs: Legs, kinematics: Kinematics) -> tuple[np.ndarray, np.ndarray] | None:
    """The hips and points of the legs from the take's kinematics, or None where they do not hold
    the feet's world rotations."""
    try:
        feet = kinematics.rows(legs.rotators[:, 2])
    except ValueError:
        return None
    at = np.column_stack([legs.points[:, :5], feet])  # hip, knee, ankle, ball and tip; the foot's row
    return kernels.placed_legs(kinematics.positions, kinematics.world, at, legs.segments[:, 3])


_FLAT_SPEED = 0.2  # m/s: ankle and ball slower than this (at the reference size) in flat stance
_FLAT_BAND = 0.02  # m: and within this of their lowest tenth


def _heel_from_take(
    points: np.ndarray, foot: np.ndarray, up: np.ndarray, frame_rate: float, mpu: float, legs: Legs, i: int
) -> np.ndarray:
    """The heel of one leg, in the foot's frame, from the take's flat stance (module docstring)."""
    ankle, ball = points[:, 1], points[:, 2]
    for looser in (1, 2, 4):  # a take with few flat frames (a jump, a fall) has them less still
        slow = looser * _FLAT_SPEED * body_scale(legs, mpu) / mpu
        band = looser * _FLAT_BAND / mpu
        flat = np.ones(len(points), bool)
        for p in (ankle, ball):
            h = p @ up
            flat &= (speeds(p, frame_rate) < slow) & (h <= np.nanpercentile(h, 10) + band)
        if flat.sum() >= 3:
            break
    if flat.sum() < 3:
        raise ValueError(
            f"{legs.legs[i].side} leg: the rest pose does not stand on its foot and the take has no flat "
            "stance (ankle and ball low and still) to find the heel from"
        )
    down = -np.einsum("fji,j->fi", foot[flat], up).mean(axis=0)  # world down in the foot's frame
    drop = float(np.median((ankle[flat] - ball[flat]) @ up))
    return down / np.linalg.norm(down) * max(drop, 0.0)


def choose_up(arrays: LegArrays, up: str | np.ndarray | None = None) -> np.ndarray:
    """The up axis as a unit vector: ``up`` given ("y", "-z" or a vector, snapped to the nearest
    signed axis), else y for ASF (the Acclaim convention), else detected (:func:`detect_up`)."""
    if up is None:
        return parse_up("y") if arrays.legs.skeleton.convention != "bvh" else detect_up(arrays)
    if isinstance(up, str):
        return parse_up(up)
    return signed_axis_vector(np.asarray(up, float))


def detect_up(arrays: LegArrays) -> np.ndarray:
    """The signed coordinate axis nearest to the mean direction from ankle to hip over the take."""
    v = (arrays.hips - arrays.points[:, :, 1]).reshape(-1, 3)
    v = v[np.isfinite(v).all(1)]
    if not len(v):
        raise ValueError("cannot detect the up axis of a take without finite frames: give it (up=, --up)")
    return signed_axis_vector(v.mean(0))


def speeds(p: np.ndarray, frame_rate: float, *, central: bool = False) -> np.ndarray:
    """Speed (..., frames) of points (..., frames, 3), in their unit per second: the larger of the
    distances to the frames before and after (one frame: 0), so that neither difference quotient
    finds it faster; with ``central``, the central difference (numpy.gradient's: one-sided at the
    ends).  In C: :func:`mtcore.footskate.point_speeds`, which measures chosen points of the legs'
    (legs, frames, 5, 3) in place."""
    p = np.asarray(p, dtype=float)
    tracks = p.reshape(-1, p.shape[-2], 1, 3)
    speed = kernels.point_speeds(tracks, [0], frame_rate, central=central)
    return (speed[1] if central else speed).reshape(p.shape[:-1])


@dataclass(frozen=True, eq=False)
class Ground:
    """The floor plane and where each foot's contact points rest above it (file units).

    A point p is ``p . up - p . slope - level`` above the floor (``slope``
    is the floor's gradient, perpendicular to ``up``); ``clearance`` (legs, 3)
    is the height at which each leg's heel, ball and toe tip rest on it.
    """

    up: tuple[float, float, float]
    level: float
    slope: tuple[float, float, float]
    clearance: np.ndarray

    def above(self, p: np.ndarray) -> np.ndarray:
        """Distance of points (..., 3) above the floor plane, along up."""
        out = along(p, np.asarray(self.up) - np.asarray(self.slope))
        out -= self.level
        return out

    def heights(self, points: np.ndarray) -> np.ndarray:
        """Heights (legs, frames, 3) of heel, ball and toe tip above where they rest,
        from leg points (legs, frames, 5, 3)."""
        return self.above(points[:, :, [3, 2, 4]]) - self.clearance[:, None, :]

    @property
    def tilt_degrees(self) -> float:
        """How far the floor leans from level, in degrees."""
        return float(np.degrees(np.arctan(np.linalg.norm(self.slope))))


_REST_SPEED = 0.1  # m/s: a contact point slower than this (at the reference size) may be resting
_FIT_BAND = 0.015  # m: resting samples more than this above the fitted floor are not on it
_SLOPE_PRIOR = 0.15  # m: a horizontal spread of this much halves the fitted tilt (ridge)
_MAX_TILT = np.tan(np.radians(5.0))
_FIT_SAMPLES = 50_000


def fit_ground(
    arrays: LegArrays,
    frame_rate: float,
    meters_per_unit: float,
    *,
    up: str | np.ndarray | None = None,
    floor: float | None = None,
) -> Ground:
    """The ground of a take (see :class:`Ground` and the module docstring).

    ``up``: an axis ("y", "-z"...) or vector; default y for ASF (the Acclaim
    convention), detected for BVH (:func:`detect_up`).  ``floor``: the floor's
    level along up in file units (then level, untilted); default fitted to
    the resting contact points.  Raises ValueError for a take of fewer than
    two frames, or a given floor above the ankles.
    """
    legs = arrays.legs
    frames = arrays.points.shape[1]
    if frames < 2:
        raise ValueError(f"a take of {frames} frame(s) has no resting feet to find the floor from: give more frames")
    up_vector = choose_up(arrays, up)
    scale = body_scale(legs, meters_per_unit)
    has_tip = legs.points[:, 4] >= 0
    needed = max(3, round(0.05 * frame_rate))  # a point that never rests (a run on the balls): its slowest low frames
    resting = kernels.resting_points(
        arrays.points, has_tip, up_vector, frame_rate, meters_per_unit, _REST_SPEED * scale, needed
    )
    if floor is not None:
        vertical = along(arrays.points[:, :, 2:], up_vector)[:, :, [1, 0, 2]]  # ball, heel, tip: heel, ball, tip
        ankles = along(arrays.points[:, :, 1], up_vector)
        median_ankle = float(np.nanmedian(ankles))
        if floor > median_ankle:
            raise ValueError(
                f"the floor at {floor:g} (along {axis_name(up_vector)}) is above the character: its ankles are at "
                f"{median_ankle:.4g} (median over the take, file units)"
            )
        clearance = np.zeros((len(legs), 3))
        for i in range(len(legs)):
            for k in range(3):
                if resting[i, :, k].any():
                    clearance[i, k] = max(0.0, float(np.median(vertical[i, resting[i, :, k], k])) - floor)
        return Ground(_triple(up_vector), float(floor), (0.0, 0.0, 0.0), clearance)
    band, prior = _FIT_BAND * scale / meters_per_unit, _SLOPE_PRIOR * scale / meters_per_unit
    level, slope, clearance = kernels.fit_floor(
        arrays.points, resting, has_tip, up_vector, band, prior, _FIT_SAMPLES, _MAX_TILT
    )
    return Ground(_triple(up_vector), level, _triple(slope), clearance)


def _triple(v: np.ndarray) -> tuple[float, float, float]:
    return float(v[0]), float(v[1]), float(v[2])
