"""Footskate cleanup of legs over frames, in C (Kovar, Schreiner & Gleicher, SCA 2002).

Array level: a leg is a chain of four joints turning the thigh, shin, foot
and toes (see :class:`LegChain`); motiontheater builds the chains and the
arrays from a skeleton and a motion, and plans the footplants.

Conventions (those of :func:`mtcore.kinematics.forward_kinematics`): a
joint's local rotation is L = C M C^T, C its axis frame and M the rotation of
its rotation channels applied in order about fixed axes; its world rotation
is its parent's times L; a segment's rest vector, in the frame of the joint
that turns it, is the difference of rest positions (rest rotations are the
identity).  Angles are radians.  Lengths are any one unit.

Shapes: ``hips`` (legs, frames, 3) the hip points; ``parents`` (legs, frames,
3, 3) the world rotations of each hip joint's parent; ``angles`` (legs,
frames, 4, 3) the rotation channels of hip, knee, ankle and toe joints in the
order they apply (unused entries 0).  Points are (legs, frames, 5, 3): knee,
ankle, ball, heel, toe tip.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from . import _checks
from ._cdata import c_array
from ._mtcore import ffi, lib
from ._parallel import run_all, thread_count
from ._status import check

__all__ = [
    "POINTS",
    "CleanupOptions",
    "LegChain",
    "LegPlan",
    "PlantThresholds",
    "adjust_root",
    "cleanup",
    "fit_floor",
    "leg_points",
    "placed_legs",
    "plan_leg",
    "plant_masks",
    "point_speeds",
    "resting_points",
    "solve_leg",
    "write_channels",
]

POINTS = ("knee", "ankle", "ball", "heel", "tip")
_PARALLEL_MIN_FRAMES = 1000  # frames below which the second leg's thread costs more than it gains
SEGMENTS = ("thigh", "shin", "ball", "heel", "toes")
JOINTS = ("hip", "knee", "ankle", "toe")


@dataclass(frozen=True, eq=False)
class LegChain:
    """One leg as the kernels take it (see mtcore.h, ``struct mt_leg``).

    ``axis`` (4, 3, 3): C of the hip, knee, ankle and toe joints; ``axes``
    (4, 3) int: the axis (0 x, 1 y, 2 z) of each rotation channel, in the
    order they apply, -1 past the last; ``segments`` (5, 3): hip -> knee in
    the hip joint's frame, knee -> ankle in the knee's, ankle -> ball and
    ankle -> heel in the ankle's, ball -> tip in the toe's (zero: no tip).
    A toe joint without channels is no toe joint.  Hip and knee need at least
    one channel; channels of a joint with three must not repeat an axis
    twice in a row, nor, with fewer, at all.
    """

    axis: np.ndarray
    axes: np.ndarray
    segments: np.ndarray

    def __post_init__(self) -> None:
        axis = np.ascontiguousarray(self.axis, dtype=np.float64)
        axes = np.ascontiguousarray(self.axes, dtype=np.intc)
        segments = np.ascontiguousarray(self.segments, dtype=np.float64)
        for name, a, shape in (("axis", axis, (4, 3, 3)), ("axes", axes, (4, 3)), ("segments", segments, (5, 3))):
            if a.shape != shape:
                raise ValueError(f"LegChain.{name} must have shape {shape}, got {a.shape}")
        if not (np.isfinite(axis).all() and np.isfinite(segments).all()):
            raise ValueError("LegChain axis and segments must be finite")
        for j, (joint, row) in enumerate(zip(JOINTS, axes.tolist())):  # twelve numbers: checked as a list
            count = self.count(j, axes)
            used = row[:count]
            if any(a != -1 for a in row[count:]) or any(not 0 <= a <= 2 for a in used):
                raise ValueError(
                    f"LegChain.axes[{j}] ({joint}) must list axes 0-2 then -1 for unused entries, got {row}"
                )
            if (count < 3 and len(set(used)) < count) or (count == 3 and (used[0] == used[1] or used[1] == used[2])):
                raise ValueError(f"LegChain.axes[{j}] ({joint}) repeats an axis: {used}")
        if self.count(0, axes) == 0 or self.count(1, axes) == 0:
            raise ValueError("the hip and knee joints need at least one rotation channel")
        for name, a in (("axis", axis), ("axes", axes), ("segments", segments)):
            a.flags.writeable = False
            object.__setattr__(self, name, a)

    @staticmethod
    def count(joint: int, axes: np.ndarray) -> int:
        """Rotation channels of a joint (its entries before the first -1)."""
        row = list(axes[joint])
        return row.index(-1) if -1 in row else 3

    def channels(self, joint: int) -> int:
        """Rotation channels of joint 0-3 (hip, knee, ankle, toe)."""
        return self.count(joint, self.axes)


@dataclass(frozen=True)
class CleanupOptions:
    """Everything the cleanup needs besides the legs and the frames (lengths in the arrays' unit).

    The floor: a point p is at height ``p . up - p . slope - level`` above it
    (``up`` a unit vector, ``slope`` the floor's gradient, perpendicular to
    up).  ``blend``: frames over which adjustments fade in and out where
    constraints switch; ``root_window``: half-width in frames of the moving
    mean that smooths the root's adjustment (applied twice), ``root_passes``:
    how many times what is still short is smoothed in before the last
    per-frame correction; ``knee_soft``: radians short of full extension at
    which a knee stops straightening (unless the input's is straighter);
    ``knee_keep``: the share of the input's knee bend that the root moves to
    keep where a leg is constrained.
    """

    up: tuple[float, float, float] = (0.0, 1.0, 0.0)
    slope: tuple[float, float, float] = (0.0, 0.0, 0.0)
    level: float = 0.0
    blend: int = 24
    root_window: int = 6
    root_passes: int = 3
    knee_soft: float = math.radians(3.0)
    knee_keep: float = 0.5

    def __post_init__(self) -> None:
        up, slope = np.asarray(self.up, float), np.asarray(self.slope, float)
        if up.shape != (3,) or not np.isfinite(up).all() or abs(np.linalg.norm(up) - 1) > 1e-9:
            raise ValueError(f"up must be a unit vector of 3, got {self.up}")
        if slope.shape != (3,) or not np.isfinite(slope).all() or abs(slope @ up) > 1e-9:
            raise ValueError(f"slope must be a vector of 3 perpendicular to up, got {self.slope}")
        if not math.isfinite(self.level):
            raise ValueError(f"level must be finite, got {self.level}")
        for name in ("blend", "root_window", "root_passes"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
                raise ValueError(f"{name} must be a whole number >= 0, got {value!r}")
        if not 0 <= self.knee_soft < math.pi / 2:
            raise ValueError(f"knee_soft must be in [0, pi/2) radians, got {self.knee_soft}")
        if not 0 <= self.knee_keep <= 1:
            raise ValueError(f"knee_keep must be in [0, 1], got {self.knee_keep}")

    def struct(self):
        """The options as the kernels take them (``struct mt_footskate``)."""
        opt = ffi.new("struct mt_footskate *")
        opt.up = list(self.up)
        opt.slope = list(self.slope)
        opt.level = self.level
        opt.blend = self.blend
        opt.root_window = self.root_window
        opt.root_passes = self.root_passes
        opt.knee_soft = self.knee_soft
        opt.knee_keep = self.knee_keep
        return opt


@dataclass(frozen=True)
class PlantThresholds:
    """Footplant detection's thresholds (``struct mt_plant_thresholds``), in the samples' units.

    A frame is *sure* when its height is below ``sure_height`` and its central
    speed below ``sure_speed``; *close* when its height is below ``height`` and
    its speed below ``speed``, or sure; *firm* likewise with ``firm_height``
    and ``firm_speed`` (which must not exceed height and speed: firm frames are
    close).  Plants at most ``gap`` frames apart merge when every frame between
    is slower than ``merge_speed``; a plant's ends more than ``rise`` above its
    lowest frame are cut; plants shorter than ``shortest`` frames are dropped
    unless they hold a sure frame.
    """

    sure_height: float
    sure_speed: float
    height: float
    speed: float
    firm_height: float
    firm_speed: float
    merge_speed: float
    rise: float
    gap: int
    shortest: int

    def __post_init__(self) -> None:
        for name in ("gap", "shortest"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
                raise ValueError(f"{name} must be a whole number >= 0, got {value!r}")
        if not (self.firm_height <= self.height and self.firm_speed <= self.speed):
            raise ValueError("firm_height and firm_speed must not exceed height and speed (firm frames are close)")

    def struct(self):
        """The thresholds as the kernel takes them."""
        th = ffi.new("struct mt_plant_thresholds *")
        for name in (
            "sure_height",
            "sure_speed",
            "height",
            "speed",
            "firm_height",
            "firm_speed",
            "merge_speed",
            "rise",
        ):
            setattr(th, name, float(getattr(self, name)))
        th.gap, th.shortest = int(self.gap), int(self.shortest)
        return th


@dataclass(frozen=True, eq=False)
class LegPlan:
    """What phases 1 and 2 give for one leg (see :func:`plan_leg`)."""

    enforced: np.ndarray
    goal: np.ndarray
    turn: np.ndarray
    weight: np.ndarray
    reach: np.ndarray
    knee: np.ndarray


def _plan_shapes(frames: int) -> dict[str, tuple[int, ...]]:
    return {"enforced": (frames, 2, 3), "goal": (frames, 3), "turn": (frames, 3), "weight": (frames,),
            "reach": (frames,), "knee": (4,)}  # fmt: skip


def _new_plans(legs: int, frames: int) -> tuple[dict[str, np.ndarray], list[LegPlan]]:
    """Plans of ``legs`` legs whose fields are views of arrays over the legs (returned by name), so
    that the phase after them takes the legs' arrays without stacking copies."""
    fields = {name: np.empty((legs, *shape)) for name, shape in _plan_shapes(frames).items()}
    return fields, [LegPlan(**{name: a[i] for name, a in fields.items()}) for i in range(legs)]


def _output(a, name: str, shape: tuple[int, ...]) -> None:
    """Check an output array given: float64, C-contiguous, writeable, of the shape the kernel fills."""
    if not (isinstance(a, np.ndarray) and a.dtype == np.float64 and a.flags.c_contiguous and a.flags.writeable):
        raise ValueError(f"{name} must be a writeable C-contiguous float64 array")
    if a.shape != shape:
        raise ValueError(f"{name} must have shape {shape}, got {a.shape}")


@functools.lru_cache(maxsize=64)
def _leg_struct(chains: tuple[LegChain, ...]):
    """The legs as the kernels take them, made once for the same chains (a skeleton's, on each of
    its takes; the kernels only read them)."""
    legs = ffi.new("struct mt_leg[]", max(len(chains), 1))
    for leg, chain in zip(legs, chains):
        ffi.memmove(leg.axis, chain.axis.tobytes(), 4 * 9 * 8)
        ffi.memmove(leg.axes, chain.axes.tobytes(), 4 * 3 * ffi.sizeof("int"))
        ffi.memmove(leg.segment, chain.segments.tobytes(), 5 * 3 * 8)
    return legs


def _doubles(a, name: str, shape: tuple[int, ...]) -> np.ndarray:
    out = np.ascontiguousarray(a, dtype=np.float64)
    if out.shape != shape:
        raise ValueError(f"{name} must have shape {shape}, got {out.shape}")
    return out


def _leg_frames(chain, hips, parents, angles) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """One leg's arrays, checked: hips (frames, 3), parents (frames, 3, 3), angles (frames, 4, 3)."""
    if not isinstance(chain, LegChain):
        raise TypeError(f"chain must be a LegChain, got {type(chain).__name__}")
    hips = np.ascontiguousarray(hips, dtype=np.float64)
    if hips.ndim != 2 or hips.shape[1] != 3:
        raise ValueError(f"hips must have shape (frames, 3), got {hips.shape}")
    frames = hips.shape[0]
    return hips, _doubles(parents, "parents", (frames, 3, 3)), _doubles(angles, "angles", (frames, 4, 3)), frames


def leg_points(chains, hips, parents, angles, *, feet: bool = False):
    """World points (legs, frames, 5, 3) of the legs: knee, ankle, ball, heel and toe tip
    (the ball's position where the leg has no toe tip); with ``feet=True`` also the feet's world
    rotations (legs, frames, 3, 3).  NaN in, NaN out."""
    chains = tuple(chains)
    if not chains or not all(isinstance(c, LegChain) for c in chains):
        raise TypeError("chains must be one or more LegChain")
    n = len(chains)
    hips = np.ascontiguousarray(hips, dtype=np.float64)
    if hips.ndim != 3 or hips.shape[0] != n or hips.shape[2] != 3:
        raise ValueError(f"hips must have shape ({n}, frames, 3), got {hips.shape}")
    frames = hips.shape[1]
    parents = _doubles(parents, "parents", (n, frames, 3, 3))
    angles = _doubles(angles, "angles", (n, frames, 4, 3))
    out = np.empty((n, frames, 5, 3))
    rotations = np.empty((n, frames, 3, 3)) if feet else None
    check(
        lib.mt_leg_points(
            _leg_struct(chains),
            n,
            frames,
            c_array(hips),
            c_array(parents),
            c_array(angles),
            c_array(out),
            c_array(rotations),
        ),
        "mt_leg_points",
    )
    return (out, rotations) if feet else out


def placed_legs(positions, world, at, heels) -> tuple[np.ndarray, np.ndarray]:
    """The hips (legs, frames, 3) and points (legs, frames, 5, 3, as :func:`leg_points` gives
    them) of legs placed by forward kinematics: ``positions`` (frames, joints, 3) and ``world``
    (frames, kept, 3, 3) as :func:`mtcore.kinematics.world_kinematics` gives them; ``at`` (legs,
    6) the joints at each leg's hip, knee, ankle, ball and toe tip (-1: no tip, the ball's place)
    and the row of ``world`` that turns the foot; ``heels`` (legs, 3) the heel from the ankle in
    the foot's frame.  The same points as :func:`leg_points` of the legs' angles, without
    working out the legs again (``mt_placed_legs``)."""
    p = _checks.real(positions, "positions", ("frames", None, 3))
    frames, joints = p.shape[:2]
    w = _checks.real(world, "world", (frames, None, 3, 3))
    where = _checks.integers(at, "at", (None, 6), -1, max(joints, w.shape[1]))
    legs = len(where)
    h = _checks.real(heels, "heels", (legs, 3))
    hips, points = np.empty((legs, frames, 3)), np.empty((legs, frames, 5, 3))
    status = lib.mt_placed_legs(c_array(p), frames, joints, c_array(w), w.shape[1], legs,
                                c_array(where, "long long[]"), c_array(h), c_array(hips), c_array(points))  # fmt: skip
    if status == lib.MT_EINVAL:  # the kernel checks each leg's joints and row
        raise ValueError(
            f"at must name joints 0 .. {joints - 1} (the tip -1 where there is none) and world rows "
            f"0 .. {w.shape[1] - 1}, got {where.tolist()}"
        )
    check(status, "mt_placed_legs")
    return hips, points


def _clearance(clearance) -> np.ndarray:
    out = _doubles(clearance, "clearance", (3,))
    if not np.isfinite(out).all():
        raise ValueError(f"clearance must be finite, got {out.tolist()}")
    return out


def _planted(planted, frames: int) -> np.ndarray:
    out = np.asarray(planted)
    if out.shape != (frames, 2) or out.dtype.kind not in "bui":
        raise ValueError(f"planted must be booleans of shape ({frames}, 2), got {out.dtype} {out.shape}")
    return np.ascontiguousarray(out != 0, dtype=np.uint8)


def _points(points, frames: int) -> np.ndarray:
    return _doubles(points, "points", (frames, 5, 3))


def plan_leg(
    chain, angles, points, planted, targets, clearance, options: CleanupOptions, *, out: LegPlan | None = None
) -> LegPlan:
    """Phases 1 and 2 for one leg (``mt_footskate_plan``), of its angles (frames, 4, 3) and
    points (frames, 5, 3) as :func:`leg_points` gives them.

    ``planted`` (frames, 2): whether the heel and the ball are planted;
    ``targets`` (frames, 2, 3): where (read where planted: the mean position
    over the plant, as motiontheater gives it); ``clearance`` (3,): the
    heights at which heel, ball and toe tip rest above the floor.  Returns
    the targets as enforced (on the floor, a new one at the foot's
    heel-to-ball length from the other's; NaN where not planted), the ankle's
    goal (frames, 3), the foot's turn (frames, 3) as a rotation vector (its
    goal rotation is the turn times its rotation now), each frame's blend
    weight (1 constrained, 0 untouched), the knee's reach (the longest
    hip-to-ankle distance the root must keep it within) and the knee's hinge
    axis in the thigh's frame with the side it bends to, (4,).  ``out``: a plan to write into
    (C-contiguous float64 arrays of those shapes), e.g. views of arrays of both legs.
    """
    if not isinstance(chain, LegChain):
        raise TypeError(f"chain must be a LegChain, got {type(chain).__name__}")
    angles = np.ascontiguousarray(angles, dtype=np.float64)
    if angles.ndim != 3 or angles.shape[1:] != (4, 3):
        raise ValueError(f"angles must have shape (frames, 4, 3), got {angles.shape}")
    frames = angles.shape[0]
    points = _points(points, frames)
    planted = _planted(planted, frames)
    targets = _doubles(targets, "targets", (frames, 2, 3))
    if not np.isfinite(targets[planted.astype(bool)]).all():
        raise ValueError("targets must be finite where planted")
    plan = _new_plans(1, frames)[1][0] if out is None else out
    for name, shape in _plan_shapes(frames).items():
        _output(getattr(plan, name), f"out.{name}", shape)
    check(
        lib.mt_footskate_plan(
            _leg_struct((chain,)),
            frames,
            c_array(angles),
            c_array(points),
            c_array(planted, "unsigned char[]"),
            c_array(targets),
            c_array(_clearance(clearance)),
            options.struct(),
            c_array(plan.enforced),
            c_array(plan.goal),
            c_array(plan.turn),
            c_array(plan.weight),
            c_array(plan.reach),
            c_array(plan.knee),
        ),
        "mt_footskate_plan",
    )
    return plan


def adjust_root(hips, goals, reaches, weights, options: CleanupOptions) -> np.ndarray:
    """Phase 3 (``mt_footskate_root``): the root's translation (frames, 3) that lets one or two
    legs reach their ankle goals: hips, goals (legs, frames, 3), reaches and weights (legs,
    frames) as :func:`plan_leg` gives them; frames of weight 0 do not constrain."""
    hips = np.ascontiguousarray(hips, dtype=np.float64)
    if hips.ndim != 3 or hips.shape[0] not in (1, 2) or hips.shape[2] != 3:
        raise ValueError(f"hips must have shape (1 or 2 legs, frames, 3), got {hips.shape}")
    n, frames = hips.shape[:2]
    goals = _doubles(goals, "goals", (n, frames, 3))
    reaches = _doubles(reaches, "reaches", (n, frames))
    weights = _doubles(weights, "weights", (n, frames))
    root = np.empty((frames, 3))
    check(
        lib.mt_footskate_root(
            n,
            frames,
            c_array(hips),
            c_array(goals),
            c_array(reaches),
            c_array(weights),
            options.struct(),
            c_array(root),
        ),
        "mt_footskate_root",
    )
    return root


def solve_leg(
    chain,
    hips,
    parents,
    angles,
    points,
    planted,
    plan: LegPlan,
    root,
    clearance,
    options: CleanupOptions,
    *,
    out: np.ndarray | None = None,
) -> np.ndarray:
    """Phases 4 and 5 for one leg (``mt_footskate_solve``): the new angles (frames, 4, 3),
    the input's bit for bit in frames that need no change.  ``points`` as for :func:`plan_leg`;
    ``root`` (frames, 3) is the root's translation from :func:`adjust_root`; ``out``: an array to
    write them into (C-contiguous float64)."""
    hips, parents, angles, frames = _leg_frames(chain, hips, parents, angles)
    points = _points(points, frames)
    planted = _planted(planted, frames)
    root = _doubles(root, "root", (frames, 3))
    goal = _doubles(plan.goal, "plan.goal", (frames, 3))
    turn = _doubles(plan.turn, "plan.turn", (frames, 3))
    weight = _doubles(plan.weight, "plan.weight", (frames,))
    knee = _doubles(plan.knee, "plan.knee", (4,))
    if out is None:
        out = np.empty_like(angles)
    _output(out, "out", angles.shape)
    check(
        lib.mt_footskate_solve(
            _leg_struct((chain,)),
            frames,
            c_array(hips),
            c_array(parents),
            c_array(angles),
            c_array(points),
            c_array(planted, "unsigned char[]"),
            c_array(goal),
            c_array(turn),
            c_array(weight),
            c_array(knee),
            c_array(root),
            c_array(_clearance(clearance)),
            options.struct(),
            c_array(out),
        ),
        "mt_footskate_solve",
    )
    return out


def cleanup(
    chains,
    hips,
    parents,
    angles,
    points,
    planted,
    targets,
    clearance,
    options: CleanupOptions,
    *,
    workers: int | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Footskate cleanup of one or two legs over frames: (angles, root, enforced).

    The arrays are those of the phases, with a leading axis of legs:
    ``hips`` (legs, frames, 3), ``parents`` (legs, frames, 3, 3), ``angles``
    (legs, frames, 4, 3), ``points`` (legs, frames, 5, 3), ``planted``
    (legs, frames, 2), ``targets`` (legs, frames, 2, 3), ``clearance`` (legs,
    3).  Returns the new angles, the root's translation to add (frames, 3) and
    the enforced targets (legs, frames, 2, 3): :func:`plan_leg` per leg,
    :func:`adjust_root`, :func:`solve_leg` per leg; the legs in two threads
    (``workers`` as for the filters: None for every core on takes of a
    thousand frames or more, 1 for the calling thread alone).
    """
    chains = tuple(chains)
    if len(chains) not in (1, 2):
        raise ValueError(f"cleanup takes one or two legs, got {len(chains)}")
    hips = np.ascontiguousarray(hips, dtype=np.float64)
    if hips.ndim != 3 or hips.shape[0] != len(chains) or hips.shape[2] != 3:
        raise ValueError(f"hips must have shape ({len(chains)}, frames, 3), got {hips.shape}")
    frames = hips.shape[1]
    threads = thread_count(workers, frames >= _PARALLEL_MIN_FRAMES)

    def each_leg(task):
        calls = [lambda i=i: task(i) for i in range(len(chains))]
        return run_all(calls) if threads > 1 else [call() for call in calls]

    fields, plans = _new_plans(len(chains), frames)
    each_leg(
        lambda i: plan_leg(chains[i], angles[i], points[i], planted[i], targets[i], clearance[i], options, out=plans[i])
    )
    root = adjust_root(hips, fields["goal"], fields["reach"], fields["weight"], options)
    out = np.empty((len(chains), frames, 4, 3))
    each_leg(
        lambda i: solve_leg(
            chains[i],
            hips[i],
            parents[i],
            angles[i],
            points[i],
            planted[i],
            plans[i],
            root,
            clearance[i],
            options,
            out=out[i],
        )
    )
    return out, root, fields["enforced"]


def write_channels(values, angles, solved, columns, angle_scale: float, root, root_columns) -> np.ndarray:
    """A cleanup written back to a motion's channels (``mt_footskate_write``): a new (frames,
    channels) array, ``values`` but where a leg's solved angle (``solved``, (legs, frames, 4, 3)
    as :func:`cleanup` gives them) differs from its input angle (``angles``, the same shape),
    written to its column as solved / ``angle_scale`` (``columns`` (legs, 4, 3): the column of each
    angle, -1 for none), and in the root's translation columns ``root_columns`` (3,), to which
    ``root`` (frames, 3) is added where it is not 0.  Every other value is the input's, bit for
    bit.  The columns must be distinct columns of values."""
    values = np.ascontiguousarray(values, dtype=np.float64)
    if values.ndim != 2:
        raise ValueError(f"values must have shape (frames, channels), got {values.shape}")
    frames, width = values.shape
    solved = np.ascontiguousarray(solved, dtype=np.float64)
    if solved.ndim != 4 or solved.shape[0] not in (1, 2) or solved.shape[1:] != (frames, 4, 3):
        raise ValueError(f"solved must have shape (1 or 2 legs, {frames}, 4, 3), got {solved.shape}")
    legs = solved.shape[0]
    angles = _doubles(angles, "angles", solved.shape)
    root = _doubles(root, "root", (frames, 3))
    cols = np.ascontiguousarray(columns, dtype=np.int64)
    where = np.ascontiguousarray(root_columns, dtype=np.int64)
    if cols.shape != (legs, 4, 3) or where.shape != (3,):
        raise ValueError(
            f"columns must have shape ({legs}, 4, 3) and root_columns (3,), got {cols.shape}, {where.shape}"
        )
    used = np.concatenate([cols[cols >= 0], where])
    if (cols < -1).any() or (where < 0).any() or (used >= width).any() or len(np.unique(used)) < len(used):
        raise ValueError(f"columns and root_columns must be distinct columns of the {width} channels (-1: none)")
    if not (math.isfinite(angle_scale) and angle_scale != 0):
        raise ValueError(f"angle_scale must be finite and not 0, got {angle_scale}")
    out = np.empty_like(values)
    check(
        lib.mt_footskate_write(
            legs,
            frames,
            width,
            c_array(values),
            c_array(angles),
            c_array(solved),
            c_array(cols, "long long[]"),
            angle_scale,
            c_array(root),
            c_array(where, "long long[]"),
            c_array(out),
        ),
        "mt_footskate_write",
    )
    return out


def point_speeds(points, which, frame_rate: float, *, central: bool = False):
    """Speeds of points over frames, in their unit per second (``mt_point_speeds``).

    ``points`` (tracks, frames, per_frame, 3), of which the points ``which``
    (indices below per_frame) of each frame are measured.  Returns (tracks,
    len(which), frames): the larger of the distances to the frames before and
    after, times ``frame_rate``, so that neither difference quotient finds a
    point faster (a single frame: 0); with ``central``, also the length of
    the central difference (numpy.gradient's: one-sided at the ends) times
    ``frame_rate``.  NaN in, NaN out.
    """
    points = np.ascontiguousarray(points, dtype=np.float64)
    if points.ndim != 4 or points.shape[3] != 3:
        raise ValueError(f"points must have shape (tracks, frames, per_frame, 3), got {points.shape}")
    tracks, frames, per_frame = points.shape[:3]
    wanted = np.asarray(which)
    if wanted.ndim != 1 or wanted.dtype.kind not in "iu" or not ((wanted >= 0) & (wanted < per_frame)).all():
        raise ValueError(f"which must list points below {per_frame}, got {which!r}")
    picked = np.ascontiguousarray(wanted, dtype=np.uintp)
    if not math.isfinite(frame_rate):
        raise ValueError(f"frame_rate must be finite, got {frame_rate}")
    speed = np.empty((tracks, len(picked), frames))
    middle = np.empty_like(speed) if central else None
    check(
        lib.mt_point_speeds(
            c_array(points),
            tracks,
            frames,
            per_frame,
            c_array(picked, "size_t[]"),
            len(picked),
            float(frame_rate),
            c_array(speed),
            c_array(middle),
        ),
        "mt_point_speeds",
    )
    return (speed, middle) if central else speed


def plant_masks(heights, speed, central, thresholds: PlantThresholds) -> np.ndarray:
    """Footplant masks (rows, frames) bool (``mt_plant_masks``) of rows of samples: ``heights``
    above rest, ``speed`` the larger of the forward and backward differences' and ``central`` the
    central difference's (as :func:`point_speeds` gives them), all (rows, frames), by
    ``thresholds`` (see :class:`PlantThresholds`).  Each plant's lowest height is the minimum over
    it, gaps merged included, NaN if any is; NaN compares false."""
    heights = np.ascontiguousarray(heights, dtype=np.float64)
    if heights.ndim != 2:
        raise ValueError(f"heights must have shape (rows, frames), got {heights.shape}")
    speed = _doubles(speed, "speed", heights.shape)
    central = _doubles(central, "central", heights.shape)
    if not isinstance(thresholds, PlantThresholds):
        raise TypeError(f"thresholds must be PlantThresholds, got {type(thresholds).__name__}")
    rows, frames = heights.shape
    mask = np.empty((rows, frames), np.uint8)
    check(
        lib.mt_plant_masks(
            c_array(heights),
            c_array(speed),
            c_array(central),
            rows,
            frames,
            thresholds.struct(),
            c_array(mask, "unsigned char[]"),
        ),
        "mt_plant_masks",
    )
    return mask.view(bool)


def _contact_legs(points, tips, up) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Points (legs, frames, 5, 3), which legs have a toe tip as C ints, and up as a signed axis."""
    p = np.ascontiguousarray(points, dtype=np.float64)
    if p.ndim != 4 or p.shape[2:] != (5, 3):
        raise ValueError(f"points must have shape (legs, frames, 5, 3), got {p.shape}")
    t = _checks.flags(tips, "tips", p.shape[0])
    u = _doubles(up, "up", (3,))
    if np.count_nonzero(u) != 1 or abs(u).max() != 1.0:
        raise ValueError(f"up must be a signed coordinate axis such as (0, 1, 0), got {u.tolist()}")
    return p, t, u


def resting_points(points, tips, up, frame_rate: float, meters_per_unit: float, rest_speed: float, needed: int):
    """Where each leg's heel, ball and toe tip rest: (legs, frames, 3) booleans, ``points`` (legs,
    frames, 5, 3) as :func:`leg_points` gives them, ``tips`` (legs) which legs have a toe tip.  A
    point rests where it is slower than ``rest_speed`` m/s; one that rests so in fewer than
    ``needed`` frames rests in the ``needed`` slowest of its frames no higher along ``up`` (a
    signed coordinate axis) than its 20th percentile (``mt_resting_points``, csrc/mtcore.h)."""
    p, t, u = _contact_legs(points, tips, up)
    legs, frames = p.shape[:2]
    rate, meters = float(frame_rate), float(meters_per_unit)
    if not (rate > 0 and meters > 0 and math.isfinite(rate * meters)):
        raise ValueError(f"frame_rate and meters_per_unit must be positive, got {frame_rate}, {meters_per_unit}")
    resting = np.zeros((legs, frames, 3), dtype=np.uint8)
    status = lib.mt_resting_points(c_array(p), legs, frames, c_array(t, "int[]"), c_array(u), rate, meters,
                                   float(rest_speed), _checks.integer(needed, "needed", 0),
                                   c_array(resting, "unsigned char[]"))  # fmt: skip
    check(status, "mt_resting_points")
    return resting.view(bool)


def fit_floor(points, resting, tips, up, band: float, prior: float, samples: int, max_tilt: float):
    """The floor under the resting contact points (``resting`` as :func:`resting_points` gives
    it): (level, slope (3,), clearance (legs, 3)) by least squares with a rest height per point,
    refitted twice without the samples more than ``band`` above the fit (``mt_fit_floor``,
    csrc/mtcore.h); ValueError where nothing rests."""
    p, t, u = _contact_legs(points, tips, up)
    legs, frames = p.shape[:2]
    rests = np.ascontiguousarray(resting, dtype=np.uint8)
    if rests.shape != (legs, frames, 3):
        raise ValueError(f"resting must have shape ({legs}, {frames}, 3), got {rests.shape}")
    if not rests.any():
        raise ValueError("no contact point rests in any frame: there is no floor to fit")
    level, slope, clearance = ffi.new("double *"), np.zeros(3), np.zeros((legs, 3))
    status = lib.mt_fit_floor(c_array(p), c_array(rests, "unsigned char[]"), legs, frames, c_array(t, "int[]"),
                              c_array(u), float(band), float(prior), _checks.integer(samples, "samples", 1),
                              float(max_tilt), level, c_array(slope), c_array(clearance))  # fmt: skip
    check(status, "mt_fit_floor")
    return float(level[0]), slope, clearance
