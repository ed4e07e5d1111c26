"""Retargeting: a capture put on another skeleton, its root scaled to the new legs, its feet re-planted.

:func:`plan_retarget` works out, once per pair of skeletons, what each target
joint does; :func:`retarget` applies it to a motion (the per-frame work is C,
:func:`mtcore.retarget.retarget_rotations`); the step ``retarget``
(``motion.retarget(to=...)``, ``motiontheater retarget TAKE --to TARGET``,
recipes, batch) reads the target from a file.

Joints are paired by :func:`motiontheater.characters.rigs.joint_map`: the alias tables
of known rigs, or a map file.  Then, by the kind of pair:

- **Same rig** (mode "rotations"): the same joints, hierarchy, channels and
  axis frames on both sides (CMU subjects, HDM05 actors), only the bone
  lengths and directions differ.  Joint rotations carry over: every rotation
  channel is copied, so each bone's local rotation C M C^T is the source's.
- **Another rig** (mode "directions"): each mapped target joint turns so
  that the bone it drives points, in the world, where the source's bone
  points, and its twist about it follows the source's.  The rest poses may
  differ (T-pose and A-pose, splayed legs): a per-joint rest correction Q,
  the smallest rotation taking the target's rest bone onto the source's,
  makes the target's world rotation A W_s Q (W_s the source joint's world
  rotation, A the turn between the two rigs' world axes).  Where unmapped
  source joints lie between two mapped ones (a spine of three joints onto
  one of two), the bone is turned each frame onto the source's points.
  A joint with fewer than three rotation channels (CMU's knee: rx) aims its
  bone as near as its channels allow.  Unmapped target joints keep their
  rest rotation.

*The bone a joint drives* is the segment to its mapped child: the one that
continues the chain (the spine from the hips, the neck from the chest)
where both rigs have it with a length, else the line between a left and a
right child (the hips' line when the spine starts at the root, as in CMU's
ASF), else its only child, else its own bone (ASF) or its single End Site
(BVH); a joint with none of these (a mapped leaf whose rigs disagree) keeps
the rest correction of its mapped parent.

*World axes*: A is the signed permutation of axes nearest to the rotation
that best fits the two rest poses' mapped joints onto each other (Kabsch),
so that a y-up capture lands y-up on a z-up rig.  *Scale*: the root's
position is multiplied by the ratio of the legs, each the hip height of its
rest pose (the root above the lowest point, along the up axis: y, or z when
the pose is taller along z), in metres; lengths in file units then need no
conversion; yet both skeletons' length units must be known (an ASF's
stated, a BVH's detected from its size or given), for the report and the
footskate cleanup's thresholds in metres: an assumed unit is refused.

*Rest poses*: an ASF's is its calibration pose; a BVH target's is the pose
its OFFSETs draw with every rotation channel zero (not its first frame), as
for every BVH reader here.  A BVH rest pose that does not stand (its root not
above its feet: rigs whose OFFSETs lie along each bone's own axes, as LAFAN1's
and Rokoko's do) is replaced by the pose of a frame of its take that stands
(:mod:`motiontheater.characters.standing`); where none is known it cannot give
a hip height and is refused.  A game rig's static root and its offset-only
position channels are seen through its body view (:mod:`motiontheater.model.rig`).
"""

from __future__ import annotations

import dataclasses
import functools
import itertools
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Literal

import numpy as np

from mtcore.kinematics import JointTree
from mtcore.retarget import RetargetPlan as KernelPlan
from mtcore.retarget import retarget_rotations
from mtcore.rotations import unroll_euler

from ..formats.table import read_skeleton, skeleton_convention, skeleton_suffixes
from ..model import units
from ..model.motion import Motion
from ..model.registry import is_step, step
from ..model.rig import STANDING, BodyView, body_view, rest_values, rest_view, standing_frame, standing_height
from ..model.skeleton import ROTATIONS, TRANSLATIONS, Skeleton
from . import rigs
from .rigs import JointMap
from .standing import Rested, rested

MODES = ("auto", "rotations", "directions")
DEGENERATE = 1e-3
"""A segment shorter than this fraction of its rest pose's size has no direction to follow."""
"""A rest pose stands when its root is at least this fraction of its size above its lowest point."""


@dataclass(frozen=True, eq=False)
class RetargetPlan:
    """What retargeting from ``source`` to ``target`` does (see the module docstring).

    ``mode`` is "rotations" (same rig: channels copied) or "directions";
    ``align`` (3, 3) turns source world axes into target world axes;
    ``source_up`` and ``target_up`` are the up axes ("+y", "+z", ...);
    ``source_leg`` and ``target_leg`` the hip heights at rest in file units;
    ``kernel`` the C kernel's tables (None for "rotations"), whose source
    joints are those of ``source_tree``: the source's tree cut to the joints
    the target needs, ``source_joints`` (their indices in the source's
    ``joint_names``), so that no forward kinematics is done for fingers that
    nothing follows; ``copies``
    (source column, target column) pairs of copied channels; ``aims`` what
    each mapped target joint aims at, and its rest correction in degrees;
    ``notes`` what the user should know.
    """

    source: Skeleton
    target: Skeleton
    joint_map: JointMap
    mode: str
    align: np.ndarray
    source_up: str
    target_up: str
    source_leg: float
    target_leg: float
    kernel: KernelPlan | None
    source_tree: JointTree | None
    source_joints: np.ndarray | None
    copies: tuple[tuple[int, int], ...]
    aims: dict[str, tuple[str, float]]
    notes: tuple[str, ...]

    @property
    def scale(self) -> float:
        """Target leg over source leg, in file units: what root positions are multiplied by."""
        return self.target_leg / self.source_leg

    @property
    def leg_ratio(self) -> float:
        """Target leg over source leg, in metres."""
        return (self.target_leg * self.target.meters_per_unit) / (self.source_leg * self.source.meters_per_unit)

    def describe(self) -> str:
        """The plan as text: rigs, joint map, unmapped joints, scale factors, units and axes."""
        extra = {
            target: f"aims at {aim}" + (f", rest turned {degrees:.1f} deg" if degrees >= 0.05 else "")
            for target, (aim, degrees) in self.aims.items()
        }
        if self.mode == "rotations":
            mode = "rotations (the same rig: rotation channels copied, so local rotations carry over)"
        else:
            mode = "directions (each mapped bone points where the source's does, its twist carried over)"
        s, t = self.source, self.target
        lines = [
            self.joint_map.describe(extra),
            f"mode: {mode}",
            f"units: source {_unit_text(s)}; target {_unit_text(t)}",
            f"legs (hip height at rest): source {self.source_leg:.6g} units = "
            f"{self.source_leg * s.meters_per_unit:.4f} m, target {self.target_leg:.6g} units = "
            f"{self.target_leg * t.meters_per_unit:.4f} m",
            f"scale factors: legs x {self.leg_ratio:.6g} (target / source, in metres); root positions "
            f"x {self.scale:.6g} (source file units to target file units)",
            f"up axes: source {self.source_up}, target {self.target_up}; world axes {_axes_text(self.align)}",
        ]
        lines += [f"note: {n}" for n in self.notes]
        return "\n".join(lines)


_HOW = {
    "stated": "stated by its ASF",
    "default": "the Acclaim default: its ASF states none",
    "detected": "detected from its size",
    "given": "given",
    "assumed": "assumed",
}


def _unit_text(skeleton: Skeleton) -> str:
    return (
        f"{units.label(skeleton.length_unit)} = {skeleton.meters_per_unit:.6g} m "
        f"({_HOW.get(skeleton.length_source, skeleton.length_source)})"
    )


def _axes_text(align: np.ndarray) -> str:
    if np.array_equal(align, np.eye(3)):
        return "the same"
    return ", ".join(
        f"source {axis} -> target {'-' if align[i, j] < 0 else '+'}{'xyz'[i]}"
        for j, axis in enumerate("xyz")
        for i in range(3)
        if align[i, j]
    )


@dataclass(frozen=True, eq=False)
class _Pose:
    """A skeleton's rest pose and tree for planning; points and joints are ``joint_names`` indices.

    Point j is where forward kinematics puts joint j (an ASF bone's end, a
    BVH joint itself); a joint turns about its pivot point (an ASF bone's
    start, a BVH joint itself).
    """

    skeleton: Skeleton
    rest: np.ndarray
    parent: np.ndarray
    pivot: np.ndarray
    children: tuple[tuple[int, ...], ...]
    size: float

    @classmethod
    def of(cls, skeleton: Skeleton) -> _Pose:
        tree = skeleton.tree
        parent = tree.parent
        pivot = np.arange(tree.joints) if skeleton.convention == "bvh" else np.maximum(parent, 0)
        children: list[list[int]] = [[] for _ in range(tree.joints)]
        for j in range(1, tree.joints):
            children[parent[j]].append(j)
        rest = skeleton.rest_positions()
        return cls(skeleton, rest, parent, pivot, tuple(map(tuple, children)), float(np.max(np.ptp(rest, axis=0))))

    def name(self, j: int) -> str:
        return self.skeleton.point_names[j]

    def dofs(self, j: int) -> tuple[str, ...]:
        return self.skeleton.dofs(self.skeleton.point_names[j])

    def turns(self, j: int) -> int:
        """How many rotation channels joint j has."""
        return sum(d in ROTATIONS for d in self.dofs(j))

    def vector(self, points: tuple[int, int]) -> np.ndarray:
        """From the first point to the second at rest."""
        return self.rest[points[1]] - self.rest[points[0]]

    def degenerate(self, points: tuple[int, int]) -> bool:
        return bool(np.linalg.norm(self.vector(points)) <= DEGENERATE * self.size)

    def rigid(self, joint: int, point: int) -> bool | None:
        """Whether ``point`` turns rigidly with ``joint`` (no other joint with channels turns or moves
        the segments between them); None when the point is not below the joint's pivot."""
        bvh = self.skeleton.convention == "bvh"
        k = point
        while k != self.pivot[joint]:
            if k == 0:
                return None
            turner = int(self.parent[k]) if bvh else k  # the joint that turns the segment ending at k
            if (turner != joint and self.turns(turner)) or any(d not in ROTATIONS for d in self.dofs(k)):
                return False
            k = int(self.parent[k])
        return True

    def own_bone(self, j: int) -> tuple[int, int] | None:
        """The points (from, to) of the bone joint j turns by itself: an ASF bone's own segment, a
        BVH joint's single child's offset; None for an ASF root or a BVH joint with several children."""
        if self.skeleton.convention != "bvh":
            return (int(self.pivot[j]), j) if j > 0 else None
        return (j, self.children[j][0]) if len(self.children[j]) == 1 else None

    def mapped_below(self, j: int, follow: dict[int, int]) -> list[int]:
        """The nearest mapped joints below j, in hierarchy order."""
        found: list[int] = []
        stack = list(reversed(self.children[j]))
        while stack:
            k = stack.pop()
            if k in follow:
                found.append(k)
            else:
                stack.extend(reversed(self.children[k]))
        return found


def plan_retarget(
    source: Skeleton,
    target: Skeleton,
    joint_map: JointMap | str | os.PathLike | None = None,
    *,
    mode: str = "auto",
) -> RetargetPlan:
    """The plan of retargeting motions of ``source`` onto ``target`` (see the module docstring).

    ``joint_map``: a :class:`~motiontheater.characters.rigs.JointMap`, a map file
    (TOML, see :mod:`motiontheater.characters.rigs`), or None for the alias tables.
    ``mode``: "auto" (rotations for the same rig, else directions),
    "rotations" or "directions".  Plans from the tables or a map file are
    kept for the next call with equal skeletons (a batch of takes).  Raises
    ValueError naming what is wrong: no joints in common, a map naming
    unknown joints (UnknownNameError), an unknown length unit, a rest pose
    that does not stand, "rotations" for two rigs that differ.

    Both skeletons are planned as their bodies carry them (:func:`~motiontheater.model.rig.rest_view`):
    a game rig's static root and its position channels that hold only OFFSETs are no joints to
    follow; the plan's ``source`` and ``target`` are those views.
    """
    planned = _planned_rig(rest_view(source), source.standing)[0]
    return _plan_of_views(planned, _planned_rig(rest_view(target), target.standing)[0], joint_map, mode)


def _planned_rig(view: BodyView, standing: tuple[float, ...] | None) -> tuple[Skeleton, Rested | None]:
    """The skeleton a plan works on for a rig seen from its body: the view's, or where its rest
    pose does not stand and a standing frame is known, its re-rested twin (:mod:`.standing`)."""
    skeleton = view.motion.skeleton
    if standing is None or standing_height(skeleton.rest_positions()) > STANDING:
        return skeleton, None
    twin = rested(skeleton, np.asarray(standing)[view.columns])
    return (skeleton, None) if twin is None else (twin.skeleton, twin)


def _plan_of_views(
    source: Skeleton, target: Skeleton, joint_map: JointMap | str | os.PathLike | None, mode: str
) -> RetargetPlan:
    """:func:`plan_retarget` of skeletons seen from their bodies (:mod:`motiontheater.model.rig`)."""
    if mode not in MODES:
        raise ValueError(f"mode must be one of {', '.join(MODES)}, got {mode!r}")
    if isinstance(joint_map, JointMap):
        return _plan(source, target, joint_map, mode)
    if joint_map is None:
        return _cached_plan(source, target, None, mode)
    try:
        stat = os.stat(joint_map)
    except FileNotFoundError:
        raise FileNotFoundError(f"{os.fspath(joint_map)}: no such map file") from None
    return _cached_plan(source, target, (os.fspath(joint_map), stat.st_mtime_ns, stat.st_size), mode)


@functools.lru_cache(maxsize=16)
def _cached_plan(source: Skeleton, target: Skeleton, map_file: tuple[str, int, int] | None, mode: str) -> RetargetPlan:
    pairs = rigs.joint_map(source, target, None if map_file is None else map_file[0])
    return _plan(source, target, pairs, mode)


def _known_unit(skeleton: Skeleton, side: str, flag: str) -> None:
    """ValueError unless the skeleton's length unit is known: stated, detected or given."""
    name = f"the {side} skeleton" + (f" '{skeleton.name}'" if skeleton.name else "")
    try:
        meters = skeleton.meters_per_unit
    except ValueError as e:
        raise ValueError(f"{name}: {e}") from None
    if skeleton.length_source == "assumed":
        raise ValueError(
            f"{name} has no known length unit: a BVH file states none and the size of this one "
            f"({max(skeleton.sizing().extents):.4g} units across) tells none; give it with {flag} UNIT "
            f"(Python: read it with unit=UNIT), UNIT: {units.UNIT_HELP}; it was taken for "
            f"{units.label(skeleton.length_unit)} ({meters:g} m)"
        )


def _plan(source: Skeleton, target: Skeleton, pairs: JointMap, mode: str) -> RetargetPlan:
    _known_unit(source, "source", "--unit")
    _known_unit(target, "target", "--to-unit")
    s_pose, t_pose = _Pose.of(source), _Pose.of(target)
    s_index = {n: i for i, n in enumerate(source.point_names)}
    t_index = {n: i for i, n in enumerate(target.point_names)}
    follow = {t_index[t]: s_index[s] for s, t in pairs.pairs}
    notes: list[str] = []
    align = _align(s_pose, t_pose, follow, notes)
    source_up = _up(s_pose.rest)
    target_up = align @ source_up
    source_leg = _hip_height(s_pose, source_up, "source")
    target_leg = _hip_height(t_pose, target_up, "target")
    if _up(t_pose.rest) @ target_up < 0.5:
        notes.append(
            f"the target's rest pose is taller along {_axis_name(_up(t_pose.rest))} than along the up axis "
            f"{_axis_name(target_up)} that the source's ({_axis_name(source_up)}) and the rigs' fit give it"
        )
    differs = _differs(source, target, pairs, align)
    if mode == "rotations" and differs:
        raise ValueError(f"mode 'rotations' needs the same rig on both sides, but {differs}; use mode 'directions'")
    kernel: KernelPlan | None = None
    source_tree: JointTree | None = None
    source_joints: np.ndarray | None = None
    copies: tuple[tuple[int, int], ...] = ()
    aims: dict[str, tuple[str, float]] = {}
    if mode == "rotations" or (mode == "auto" and not differs):
        chosen, copies = "rotations", _copies(source, target, pairs)
    else:
        chosen, (kernel, aims) = "directions", _kernel_plan(s_pose, t_pose, follow, align, pairs)
        kernel, source_tree, source_joints = _pruned(source.tree, kernel)
    root = target.dofs(target.root.name)
    missing = [d for d in TRANSLATIONS if d not in root]
    if missing:
        notes.append(
            f"the target's root has no {', '.join(missing)} channel: it cannot travel along "
            f"{', '.join(d[1] for d in missing)}"
        )
    return RetargetPlan(
        source=source,
        target=target,
        joint_map=pairs,
        mode=chosen,
        align=align,
        source_up=_axis_name(source_up),
        target_up=_axis_name(target_up),
        source_leg=source_leg,
        target_leg=target_leg,
        kernel=kernel,
        source_tree=source_tree,
        source_joints=source_joints,
        copies=copies,
        aims=aims,
        notes=tuple(notes),
    )


def _up(rest: np.ndarray) -> np.ndarray:
    """+y, or +z when the rest pose is taller along z (BVH is y-up by convention, some writers z-up)."""
    spans = np.ptp(rest, axis=0) if len(rest) else np.zeros(3)
    return np.array([0.0, 0.0, 1.0]) if spans[2] > spans[1] else np.array([0.0, 1.0, 0.0])


def _axis_name(v: np.ndarray) -> str:
    i = int(np.argmax(np.abs(v)))
    return ("-" if v[i] < 0 else "+") + "xyz"[i]


def _hip_height(pose: _Pose, up: np.ndarray, side: str) -> float:
    heights = pose.rest @ up
    height = float(heights[0] - heights.min())
    if not height > STANDING * pose.size:
        name = pose.skeleton.name or "(unnamed)"
        raise ValueError(
            f"the {side} skeleton '{name}' does not stand in its rest pose: its root is {height:.4g} units above "
            f"its lowest point along {_axis_name(up)}, in a pose {pose.size:.4g} units across, so its leg length "
            "(hip height at rest) cannot be measured"
            + (
                " (a BVH's rest pose is the one its OFFSETs draw, and no frame of its take was found to stand)"
                if pose.skeleton.convention == "bvh"
                else ""
            )
        )
    return height


_TURNS = [
    p
    for p in (
        np.array([[s[0] * (k == i[0]), s[1] * (k == i[1]), s[2] * (k == i[2])] for k in range(3)], float)
        for i in itertools.permutations(range(3))
        for s in itertools.product((1.0, -1.0), repeat=3)
    )
    if np.linalg.det(p) > 0
]
"""The 24 rotations that permute the coordinate axes and flip their signs."""


def _align(s_pose: _Pose, t_pose: _Pose, follow: dict[int, int], notes: list[str]) -> np.ndarray:
    """The turn of axes nearest to the rotation that best fits the mapped joints' rest pivots."""
    pairs = list(follow.items())
    x = s_pose.rest[[s_pose.pivot[s] for _, s in pairs]]
    y = t_pose.rest[[t_pose.pivot[t] for t, _ in pairs]]
    h = (y - y.mean(axis=0)).T @ (x - x.mean(axis=0))
    if len(pairs) < 3 or np.linalg.matrix_rank(h, tol=1e-9 * max(float(np.abs(h).max()), 1e-300)) < 2:
        notes.append("too few mapped joints to compare the rigs' axes: they are taken to be the same")
        return np.eye(3)
    u, _, vt = np.linalg.svd(h)
    fit = u @ np.diag([1.0, 1.0, np.linalg.det(u @ vt)]) @ vt
    return max(_TURNS, key=lambda p: float(np.sum(p * fit))).copy()


def _differs(source: Skeleton, target: Skeleton, pairs: JointMap, align: np.ndarray) -> str | None:
    """Why the two skeletons are not the same rig (None when they are)."""
    if source.convention != target.convention:
        return "one is ASF and the other BVH"
    if set(source.point_names) != set(target.point_names):
        return "their joints are not the same"
    if any(s != t for s, t in pairs.pairs) or pairs.unmapped_source or pairs.unmapped_target:
        return "the joint map does not pair every joint with the one of the same name"
    for name in source.point_names:
        if source.dofs(name) != target.dofs(name):
            return f"joint '{name}' has other channels"
        if name != source.root.name and source.parent(name) != target.parent(name):
            return f"joint '{name}' has another parent"
    s_axis = dict(zip(source.point_names, source.tree.axis))
    for name, axis in zip(target.point_names, target.tree.axis):
        if np.abs(axis - s_axis[name]).max() > 1e-9:
            return f"joint '{name}' has another axis frame"
    if not np.array_equal(align, np.eye(3)):
        return "their rest poses face other ways"
    return None


def _copies(source: Skeleton, target: Skeleton, pairs: JointMap) -> tuple[tuple[int, int], ...]:
    copies = []
    for s, t in pairs.pairs:
        s_cols = source.columns_of([s]) if source.dofs(s) else []
        t_cols = target.columns_of([t]) if target.dofs(t) else []
        copies += [(a, b) for a, b, d in zip(s_cols, t_cols, target.dofs(t)) if d in ROTATIONS]
    return tuple(copies)


def _sides(pairs: JointMap) -> dict[str, tuple[str, str]]:
    """Each target joint's side and part ("left", "thigh"), where its part is sided: as its rig names
    it, or as the pair's part says."""
    parts = pairs.target_rig.part_of()
    parts.update((t, why) for (_, t), why in zip(pairs.pairs, pairs.why) if why.startswith(("left_", "right_")))
    sides = {}
    for joint, part in parts.items():
        side, _, rest = part.partition("_")
        if side in ("left", "right") and rest:
            sides[joint] = (side, rest)
    return sides


def _kernel_plan(
    s_pose: _Pose, t_pose: _Pose, follow: dict[int, int], align: np.ndarray, pairs: JointMap
) -> tuple[KernelPlan, dict[str, tuple[str, float]]]:
    """Per target joint: its rest correction, what it aims at, whether to re-aim it each frame and
    which hinge below it swivels it; and, for the plan's description, what each aims at."""
    target = t_pose.skeleton
    n = len(target.point_names)
    follows = np.full(n, -1, np.int64)
    correction = np.zeros((n, 3, 3))
    key_points = np.full((n, 2), -1, np.int64)
    key_vector = np.zeros((n, 3))
    refit = np.zeros(n, np.uint8)
    hinge = np.full(n, -1, np.int64)
    aim = np.zeros((n, 3))
    rest_turn = np.tile(np.eye(3), (n, 1, 1))  # each joint's Q, for the joints below that have none
    aims: dict[str, tuple[str, float]] = {}
    sides = _sides(pairs)
    for j in map(int, target.tree.order):
        parent = int(t_pose.parent[j])
        own = t_pose.own_bone(j)
        if own is not None:
            aim[j] = t_pose.vector(own)
        if j not in follow:
            rest_turn[j] = rest_turn[parent] if parent >= 0 else np.eye(3)
            continue
        follows[j] = s = follow[j]
        key = _key(s_pose, t_pose, j, s, follow, sides)
        if key is None:
            rest_turn[j] = rest_turn[parent] if parent >= 0 else np.eye(3)
            what = "nothing of its own (it keeps its parent's rest correction)"
        else:
            t_points, s_points, what, rigid, child = key
            key_vector[j] = t_pose.vector(t_points)
            rest_turn[j] = _smallest_rotation(key_vector[j], align @ s_pose.vector(s_points))
            key_points[j] = s_points
            refit[j] = not rigid
            if child is not None and t_pose.turns(j) == 3 and t_pose.turns(child) == 1 and t_pose.own_bone(child):
                hinge[j] = child  # its child's key is set when the child's turn comes
        correction[j] = align.T @ rest_turn[j]
        degrees = math.degrees(math.acos(max(-1.0, min(1.0, (np.trace(rest_turn[j]) - 1) / 2))))
        aims[t_pose.name(j)] = (what, degrees)
    hinge[hinge >= 0] = np.where(key_points[hinge[hinge >= 0], 0] >= 0, hinge[hinge >= 0], -1)
    plan = KernelPlan(
        follow=follows,
        correction=correction,
        key_points=key_points,
        key_vector=key_vector,
        refit=refit,
        hinge=hinge,
        aim=aim,
        align=align,
    )
    return plan, aims


def _pruned(tree: JointTree, plan: KernelPlan) -> tuple[KernelPlan, JointTree, np.ndarray]:
    """The plan and the source tree cut to the joints it reads (those it follows, the points it aims
    at, and the joints above them), the plan's source indices renumbered to match, and the joints
    kept (indices in the whole tree)."""
    parent = tree.parent
    keep = np.zeros(tree.joints, bool)
    for j in np.concatenate([plan.follow, plan.key_points.ravel()]):
        while j >= 0 and not keep[j]:
            keep[j] = True
            j = parent[j]
    kept = np.nonzero(keep)[0]
    index = np.full(tree.joints + 1, -1, np.int64)  # index[-1] stays -1: "none" maps to itself
    index[kept] = np.arange(len(kept))
    starts = [range(tree.dof_start[j], tree.dof_start[j + 1]) for j in kept]
    dofs = np.array([c for r in starts for c in r], np.intp)
    pruned = JointTree(
        parent=index[parent[kept]],
        order=index[[j for j in tree.order if keep[j]]],
        axis=tree.axis[kept],
        direction=tree.direction[kept],
        segment=tree.segment[kept],
        dof_start=np.concatenate([[0], np.cumsum([len(r) for r in starts])]),
        dof_kind=tree.dof_kind[dofs],
        dof_column=tree.dof_column[dofs],
        angle_scale=tree.angle_scale,
        parent_frame=None if tree.parent_frame is None else tree.parent_frame[kept],
    )
    renumbered = dataclasses.replace(plan, follow=index[plan.follow], key_points=index[plan.key_points])
    return renumbered, pruned, kept


_Key = tuple[tuple[int, int], tuple[int, int], str, bool, "int | None"]


def _key(
    s_pose: _Pose, t_pose: _Pose, j: int, s: int, follow: dict[int, int], sides: dict[str, tuple[str, str]]
) -> _Key | None:
    """What target joint j aims at (see the module docstring): (target points, source points, in
    words, whether the source's points turn rigidly with its joint, the mapped child aimed at)."""
    below = []
    for c in t_pose.mapped_below(j, follow):
        t_points = (int(t_pose.pivot[j]), int(t_pose.pivot[c]))
        s_points = (int(s_pose.pivot[s]), int(s_pose.pivot[follow[c]]))
        rigid = s_pose.rigid(s, s_points[1])
        # a map that crosses the hierarchy (the child's source not below the joint's) gives no direction
        if rigid is not None and not t_pose.degenerate(t_points) and not s_pose.degenerate(s_points):
            below.append((c, t_points, s_points, rigid))
    middle = [b for b in below if t_pose.name(b[0]) not in sides]
    lateral = None if middle else _lateral(s_pose, t_pose, j, s, follow, sides)
    if lateral is not None:
        return lateral
    if below:
        c, t_points, s_points, rigid = (middle or below)[0]
        return t_points, s_points, f"{t_pose.name(c)} (source {s_pose.name(follow[c])})", rigid, c
    t_own, s_own = t_pose.own_bone(j), s_pose.own_bone(s)
    if t_own and s_own and not t_pose.degenerate(t_own) and not s_pose.degenerate(s_own):
        return t_own, s_own, "the end of its own bone", True, None
    return None


def _lateral(
    s_pose: _Pose, t_pose: _Pose, j: int, s: int, follow: dict[int, int], sides: dict[str, tuple[str, str]]
) -> _Key | None:
    """The line from a right child of j to the left one of the same part, where both rigs have it."""
    by_part = {sides[t_pose.name(c)]: c for c in t_pose.mapped_below(j, follow) if t_pose.name(c) in sides}
    for (side, part), left in by_part.items():
        right = by_part.get(("right", part))
        if side != "left" or right is None:
            continue
        t_points = (int(t_pose.pivot[right]), int(t_pose.pivot[left]))
        s_points = (int(s_pose.pivot[follow[right]]), int(s_pose.pivot[follow[left]]))
        rigid = [s_pose.rigid(s, p) for p in s_points]
        if None in rigid or t_pose.degenerate(t_points) or s_pose.degenerate(s_points):
            continue
        return t_points, s_points, f"the line {t_pose.name(right)} -> {t_pose.name(left)}", all(rigid), None
    return None


def _smallest_rotation(u: np.ndarray, w: np.ndarray) -> np.ndarray:
    """The smallest rotation taking the direction of u onto that of w (as the C kernel's)."""
    u, w = u / np.linalg.norm(u), w / np.linalg.norm(w)
    v, c = np.cross(u, w), float(u @ w)
    if c < -1 + 1e-12:
        e = np.zeros(3)
        e[int(np.argmin(np.abs(u)))] = 1.0
        axis = np.cross(u, e)
        axis /= np.linalg.norm(axis)
        return 2 * np.outer(axis, axis) - np.eye(3)
    vx = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    return np.eye(3) + vx + vx @ vx / (1 + c)


def retarget(
    motion: Motion,
    target: Skeleton,
    joint_map: JointMap | str | os.PathLike | None = None,
    *,
    mode: str = "auto",
    cleanup: bool = True,
    plan: RetargetPlan | None = None,
    workers: int | None = None,
) -> Motion:
    """``motion`` on the ``target`` skeleton (see the module docstring): a new motion of the
    target skeleton, at the motion's frame rate and frame numbers, its angles in the target's unit.

    ``joint_map``: a :class:`~motiontheater.characters.rigs.JointMap`, a map file, or
    None for the alias tables; ``mode``: "auto", "rotations" or "directions";
    ``cleanup``: re-plant the feet with the footskate cleanup step where the
    package has one; ``plan``: a plan from :func:`plan_retarget` (for many
    takes of one skeleton; it must be of this motion's skeleton and the target).
    Rotation channels come out continuous over frames.  Raises ValueError
    (see :func:`plan_retarget`).
    """
    seen, on = body_view(motion), rest_view(target)
    source, source_twin = _planned_rig(seen, motion.skeleton.standing or standing_frame(motion))
    inner, target_twin = _planned_rig(on, target.standing)
    if plan is None:
        plan = _plan_of_views(source, inner, joint_map, mode)
    elif plan.source != source or plan.target != inner:
        raise ValueError("the plan given is for other skeletons than the motion's and the target")
    moves = seen.unturned().values  # a static root's turn is the file's axes, not the body's motion
    moves = moves if source_twin is None else source_twin.into(moves)
    values = rest_values(inner, motion.frames)
    if plan.kernel is None or plan.source_tree is None:
        for a, b in plan.copies:
            values[:, b] = moves[:, a]
    else:
        retarget_rotations(
            moves, plan.source_tree, inner.tree, len(inner.channels), plan.kernel, out=values, workers=workers
        )
    if target_twin is not None:
        values = target_twin.back(values)
    if plan.kernel is not None:
        _unroll(on.motion.skeleton, values, plan.kernel.follow)
    _root_positions(Motion(source, moves, frame_rate=motion.frame_rate), plan, values)
    values.flags.writeable = False
    result = on.restore(
        Motion(on.motion.skeleton, values, frame_rate=motion.frame_rate, first_frame=motion.first_frame)
    )
    if target.convention == "bvh":
        header = motion.header if motion.skeleton.convention == "bvh" else ()
    else:
        header = (":FULLY-SPECIFIED", ":RADIANS" if target.angle_unit == "rad" else ":DEGREES")
    result = result.replace(header=header)
    if cleanup and is_step("cleanup"):
        result = result.cleanup(**_cleanup_options(plan))
    return result


def _unroll(target: Skeleton, values: np.ndarray, follow: np.ndarray) -> None:
    """Rotation channels made continuous over frames where they jump by more than a half turn: whole
    turns added, and of a joint's two Euler solutions the one nearest the frame before."""
    tree = target.tree
    half = math.pi / tree.angle_scale
    columns = [c for c, (_, dof) in enumerate(target.channels) if dof in ROTATIONS]
    if len(values) < 2 or not columns:
        return
    jumps = np.zeros(values.shape[1], bool)
    jumps[columns] = np.abs(np.diff(values[:, columns], axis=0)).max(axis=0) > half
    for j in np.nonzero(follow >= 0)[0]:
        kinds = tree.dof_kind[tree.dof_start[j] : tree.dof_start[j + 1]]
        turns = [
            (int(k), int(c))
            for k, c in zip(kinds, tree.dof_column[tree.dof_start[j] : tree.dof_start[j + 1]])
            if k <= 2
        ]
        cols = [c for _, c in turns]
        if not jumps[cols].any():
            continue
        if len(turns) == 3:
            order = "".join("xyz"[k] for k, _ in turns)
            values[:, cols] = unroll_euler(values[:, cols], order, degrees=target.angle_unit == "deg")
        else:
            values[:, cols] = np.unwrap(values[:, cols], period=2 * half, axis=0)


def _root_positions(motion: Motion, plan: RetargetPlan, values: np.ndarray) -> None:
    """The target root's translation channels: the source root's world position, turned into the
    target's axes and multiplied by the legs' ratio, less the target root's rest offset."""
    source, target = motion.skeleton, plan.target
    order = source.dofs(source.root.name)
    position = np.tile(source.tree.segment[0], (motion.frames, 1))
    for axis, dof in enumerate(TRANSLATIONS):
        if dof in order:
            position[:, axis] += motion.values[:, motion.columns(source.root.name, dof)[0]]
    wanted = plan.scale * position @ plan.align.T - target.tree.segment[0]
    root = target.dofs(target.root.name)
    for axis, dof in enumerate(TRANSLATIONS):
        if dof in root:
            values[:, target.first_column(target.root.name) + root.index(dof)] = wanted[:, axis]


def _cleanup_options(plan: RetargetPlan) -> dict:
    """Options of the cleanup step: the target's legs as the map found them, and its up axis."""
    parts = plan.joint_map.target_rig.parts
    legs = []
    for side in ("left", "right"):
        chain = [parts.get(f"{side}_{p}", (None,))[0] for p in ("thigh", "shin", "foot", "toes")]
        legs.append(chain)
    options: dict = {"up": plan.target_up.lstrip("+")}
    if all(leg[:3] and None not in leg[:3] for leg in legs):
        with_toes = all(leg[3] for leg in legs)
        options["legs"] = tuple(name for leg in legs for name in (leg if with_toes else leg[:3]))
    return options


def read_target(path: str | os.PathLike, unit: str | None = None) -> Skeleton:
    """The skeleton of a target file: an ASF, or a BVH's hierarchy (its rest pose: OFFSETs, every
    rotation channel zero), named after its file when it has no name (BVH files give none), in
    length ``unit`` when given (else as the readers settle it: an ASF's stated unit, a BVH's
    told from its size)."""
    if Path(path).suffix.lower() not in skeleton_suffixes():
        raise ValueError(f"{os.fspath(path)}: the target must be a skeleton file ({' or '.join(skeleton_suffixes())})")
    if not os.path.exists(path):
        raise FileNotFoundError(f"{os.fspath(path)}: no such target skeleton file")
    skeleton = read_skeleton(path, unit)
    return skeleton if skeleton.name else dataclasses.replace(skeleton, name=Path(path).stem)


def describe_retarget(
    motion: Motion,
    *,
    to: Path,
    map: Path | None = None,
    cleanup: bool = True,
    mode: str = "auto",
    to_unit: str | None = None,
) -> str:
    """What the step ``retarget`` would do to ``motion`` (``motiontheater retarget --dry-run``):
    the plan's description (:meth:`RetargetPlan.describe`), the footskate cleanup, and the result."""
    target = read_target(to, to_unit)
    plan = plan_retarget(motion.skeleton, target, map, mode=mode)
    if not cleanup:
        feet = "off: the feet are not re-planted"
    elif is_step("cleanup"):
        options = _cleanup_options(plan)
        legs = ",".join(options["legs"]) if "legs" in options else "found by name"
        feet = f"the footskate cleanup re-plants the feet (legs {legs}; up axis {options['up']})"
    else:
        feet = "not available in this version (no 'cleanup' step): the feet are not re-planted"
    return "\n".join(
        [
            f"retarget {motion.frames} frames ({motion.first_frame}..{motion.last_frame}, {motion.frame_rate:g} Hz) "
            f"of skeleton '{motion.skeleton.name or '(unnamed)'}' onto {os.fspath(to)}",
            plan.describe(),
            f"cleanup: {feet}",
        ]
    )


@step(
    "retarget",
    "put a take on another skeleton (.asf or .bvh): other proportions, another rig",
    frames="none",
    dry_run=describe_retarget,
    convention=lambda convention, options: skeleton_convention(options["to"]),
)
def retarget_step(
    motion: Motion,
    *,
    to: Annotated[Path, "the target skeleton: an .asf, or a .bvh whose hierarchy (and OFFSET pose) is the target"],
    map: Annotated[
        Path | None, 'a TOML map file of [joints] source = "target" names (default: built-in aliases)'
    ] = None,
    cleanup: Annotated[bool, "re-plant the feet with the footskate cleanup after retargeting"] = True,
    mode: Annotated[
        Literal["auto", "rotations", "directions"],
        "carry rotations over (the same rig) or make bones point the source's way (auto: rotations for the same rig)",
    ] = "auto",
    to_unit: Annotated[
        str | None,
        f"the target's length unit: {units.UNIT_HELP} (default: an ASF's stated, a BVH's told from its size)",
    ] = None,
) -> Motion:
    """Put the take on the skeleton of --to: a character with other proportions or another rig.

    Joints are paired by the built-in alias tables (CMU/HDM05 ASF names, the CMU BVH conversion,
    HumanIK and Mixamo, Biovision) or by a --map file (TOML: a [joints] table of source = "target"
    names; the tables fill in what it does not name). The same rig (another CMU subject, another
    HDM05 actor) gets the joint rotations as they are; another rig gets each bone pointing where
    the source's points, rest poses (T-pose, A-pose) corrected bone by bone; unmapped target
    joints keep their rest rotation. The root's position is scaled by the ratio of the legs (hip
    heights at rest) and turned to the target's up axis. A BVH target's rest pose is the one its
    OFFSETs draw (rotations zero). Both length units must be known: an ASF states its own, a BVH's
    is told from its size, or given (--unit for the take, --to-unit for the target). --dry-run
    prints the joint map, what is unmapped on each side, the scale factors and the units, and
    writes nothing.
    """
    return retarget(motion, read_target(to, to_unit), map, mode=mode, cleanup=cleanup)
