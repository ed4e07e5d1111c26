"""Skeletons: the bones of an ASF or BVH file, their rest pose, hierarchy and kinematic tables.

Forward kinematics (ASF/AMC semantics, those of the HDM05 toolbox, which the
tests reproduce to 1e-13): a joint's local rotation is C M C^T, C from its
``axis`` angles about x, y and z applied in the order of its letters, M from
its rotation dofs applied in the order the ASF lists them, both about fixed
axes; world rotations chain from the root; a bone ends at its parent's end
plus its world rotation times its unit direction times its length.  The root
is at ``:root position`` plus its translation channels.  A BVH joint's
OFFSET turns with its parent instead, and its channels R = R1 R2 R3 apply the
last first.  :attr:`Skeleton.tree` holds the tables the C kernel takes.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Hashable, Iterable
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import TypeVar

import numpy as np

from mtcore import rotations
from mtcore.kinematics import DOFS, JointTree, forward_kinematics

from .._io import PLAIN, Origin, TextStyle
from . import units as length_units
from .errors import DuplicateError, HierarchyError, UnknownNameError

T = TypeVar("T")

Vec3 = tuple[float, float, float]

ROTATIONS = ("rx", "ry", "rz")
TRANSLATIONS = ("tx", "ty", "tz")
BONE_DOFS = (*ROTATIONS, *TRANSLATIONS, "l")  # "l": translation along the bone (stretch)
ROOT_DOFS = (*TRANSLATIONS, *ROTATIONS)


@dataclass(frozen=True)
class Bone:
    """One ASF bone, in file units.

    ``direction`` need not be unit length (forward kinematics uses its unit
    vector times ``length``); ``axis`` holds the angles of the bone's local
    frame about x, y and z, applied in ``axis_order`` (e.g. "XYZ"); ``dofs`` are
    its motion channels in AMC order, from rx ry rz tx ty tz l; ``limits``
    has one (low, high) pair per dof (empty when the file gives none).
    ``extra`` keeps other keys of the bone block (bodymass, cofmass, ...) as text.
    """

    name: str
    direction: Vec3 = (0.0, 0.0, 0.0)
    length: float = 0.0
    axis: Vec3 = (0.0, 0.0, 0.0)
    axis_order: str = "XYZ"
    dofs: tuple[str, ...] = ()
    limits: tuple[tuple[float, float], ...] = ()
    id: int | None = None
    extra: tuple[tuple[str, str], ...] = ()
    end_site: bool = False  # a BVH End Site: a point with no channels


@dataclass(frozen=True)
class Root:
    """The ASF ``:root``: its channel ``order`` (lower case), axis order, position and orientation.
    ``name`` is the root's name in a BVH file ("root" in ASF, and as a key everywhere)."""

    order: tuple[str, ...] = ROOT_DOFS
    axis: str = "XYZ"
    position: Vec3 = (0.0, 0.0, 0.0)
    orientation: Vec3 = (0.0, 0.0, 0.0)
    name: str = "root"


_CMU_HIP = re.compile(r"^(?:.*:)?(l|r)hipjoint$", re.IGNORECASE)


def name_problem(name: str, convention: str) -> str | None:
    """Why a bone (ASF) or joint (BVH) name cannot be written in the convention's format, or None."""
    if convention == "bvh":
        if not name.strip() or any(c in name for c in "{}\r\n"):
            return f"joint name {name!r} cannot be written to BVH"
    elif not name or name.split() != [name] or name[0] in "#:" or name.isdigit():
        return (
            f"bone name {name!r} cannot be written to ASF/AMC: it must be one word, "
            "not all digits, not starting with '#' or ':'"
        )
    return None


@dataclass(frozen=True)
class Skeleton:
    """An ASF skeleton.

    ``bones`` are in ``:bonedata`` order; ``hierarchy`` lists (parent,
    children) with the root first and then the bones in ``bones`` order,
    children as the file lists them.  ``units`` keeps every ``:units`` key
    with its text, unknown ones included, and ``sections`` every section
    this library does not interpret (``:skin`` and the like: keyword with
    its line, then its lines), so that they are written back.  A BVH
    skeleton (``convention="bvh"``) holds each joint as a bone whose
    ``direction`` is its OFFSET, channels listed as in the file, and its end
    sites as channel-less bones named ``<joint>_End``.  Lengths and
    angles are in the file's units (see :attr:`angle_unit` and
    :attr:`meters_per_unit`).

    ``length_choice`` is (unit text, how it was chosen) when the length unit
    in effect is not the one ``units`` states: a BVH file states none, so its
    reader detects, assumes or is given one (see :mod:`motiontheater.model.units`);
    an ASF's stated unit can be overridden (``--unit``) or, where it makes
    the character absurdly sized, corrected (:func:`settle_length_unit`).
    ``units`` keeps the file's text either way, so that writers put it back.
    """

    bones: tuple[Bone, ...]
    hierarchy: tuple[tuple[str, tuple[str, ...]], ...]
    root: Root = Root()
    name: str = ""
    version: str = "1.10"
    units: tuple[tuple[str, str], ...] = (("mass", "1.0"), ("length", "1.0"), ("angle", "deg"))
    documentation: tuple[str, ...] = ()
    sections: tuple[tuple[str, tuple[str, ...]], ...] = ()
    convention: str = "asf"  # "asf", or "bvh": a joint's offset turns with its parent, see kinematics
    length_choice: tuple[str, str] | None = None
    posed: length_units.Sizing | None = field(default=None, compare=False, repr=False)
    # a frame's channels in which the figure stands, where the rest pose does not (formats.bvh)
    standing: tuple[float, ...] | None = field(default=None, compare=False, repr=False)
    # the joint that carries the body where the caller chose it (model.rig.choose_body, --body)
    body: str | None = field(default=None, compare=False, repr=False)
    style: TextStyle = field(default=PLAIN, compare=False, repr=False)  # how its ASF file was laid out
    origin: Origin | None = field(default=None, compare=False, repr=False)  # the ASF file it was read from
    _index: dict[str, int] = field(init=False, repr=False, compare=False)
    _parents: dict[str, str] = field(init=False, repr=False, compare=False)
    _children: dict[str, tuple[str, ...]] = field(init=False, repr=False, compare=False)
    _channels: tuple[tuple[str, str], ...] = field(init=False, repr=False, compare=False)
    _first_column: dict[str, int] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        index: dict[str, int] = {}
        for i, bone in enumerate(self.bones):
            if problem := name_problem(bone.name, self.convention):
                raise ValueError(problem)
            if bone.name == "root":
                raise DuplicateError("a bone may not be called 'root': the name belongs to the root")
            if bone.name in index:
                raise DuplicateError(f"bone '{bone.name}' is defined twice")
            index[bone.name] = i
            if bone.limits and len(bone.limits) != len(bone.dofs):
                raise ValueError(f"bone '{bone.name}' has {len(bone.dofs)} dofs but {len(bone.limits)} limits")
        object.__setattr__(self, "_index", index)
        object.__setattr__(self, "_parents", _parents_of(self.hierarchy, index))
        object.__setattr__(self, "_children", dict(self.hierarchy))
        # the layout is asked for on every column lookup: worked out once
        channels: list[tuple[str, str]] = []
        first: dict[str, int] = {}
        for joint in ("root", *(b.name for b in self.bones)):
            first[joint] = len(channels)
            channels.extend((joint, d) for d in (self.root.order if joint == "root" else self.bone(joint).dofs))
        object.__setattr__(self, "_channels", tuple(channels))
        if self.root.name not in first:  # a BVH root answers to its own name too ("Hips")
            first[self.root.name] = 0
        object.__setattr__(self, "_first_column", first)
        if self.length_choice is not None:
            unit, source = self.length_choice
            length_units.meters_per(unit)  # a clear message for an unknown unit, now rather than later
            if source not in length_units.SOURCES:
                raise ValueError(f"length_choice: how the unit was chosen must be one of {length_units.SOURCES}")

    @cached_property
    def bone_names(self) -> tuple[str, ...]:
        """The bones in ``:bonedata`` order."""
        return tuple(b.name for b in self.bones)

    @cached_property
    def joint_names(self) -> tuple[str, ...]:
        """The root followed by the bones in ``:bonedata`` order; the root is called "root"."""
        return ("root", *self.bone_names)

    @property
    def point_names(self) -> tuple[str, ...]:
        """``joint_names`` with the root under its own name (a BVH file's, e.g. "Hips"): what
        exported positions are called."""
        return (self.root.name, *self.bone_names)

    def bone(self, name: str) -> Bone:
        """The bone called ``name``; UnknownNameError if there is none."""
        try:
            return self.bones[self._index[name]]
        except KeyError:
            raise UnknownNameError(f"no bone '{name}' in skeleton '{self.name}'") from None

    def parent(self, name: str) -> str:
        """The parent of bone ``name`` ("root" for the root's children)."""
        self.bone(name)
        return self._parents[name]

    def children(self, name: str) -> tuple[str, ...]:
        """The joints whose parent is ``name``, as the hierarchy lists them."""
        return self._children.get(name, ())

    def dofs(self, joint: str) -> tuple[str, ...]:
        """The channels of a joint ("root", the root's own name, or a bone name), in file order."""
        return self.root.order if self.is_root(joint) else self.bone(joint).dofs

    def is_root(self, joint: str) -> bool:
        """Whether ``joint`` names the root: "root", or the name a BVH file gives it."""
        return joint == "root" or (joint == self.root.name and joint not in self._index)

    def has_joint(self, joint: str) -> bool:
        """Whether ``joint`` names the root or a bone."""
        return self.is_root(joint) or joint in self._index

    @property
    def channels(self) -> tuple[tuple[str, str], ...]:
        """The canonical layout of motion values: (joint, dof) for the root's
        channels in its order, then each bone's dofs in bone order."""
        return self._channels

    def first_column(self, joint: str) -> int:
        """The column of a joint's first channel in the canonical layout."""
        try:
            return self._first_column[joint]
        except KeyError:
            raise UnknownNameError(f"no bone '{joint}' in skeleton '{self.name}'") from None

    def columns_of(self, joints: Iterable[str] | None = None) -> list[int]:
        """The columns of the joints' channels (every joint's when None), in the order given.
        UnknownNameError for a name the skeleton lacks, ValueError for a joint without channels
        (an end site, a bone without dofs): asking to change it is a mistake worth saying."""
        if joints is None:
            return list(range(len(self.channels)))
        columns: list[int] = []
        for joint in joints:
            start, count = self.first_column(joint), len(self.dofs(joint))
            if not count:
                raise ValueError(f"joint '{joint}' has no channels (it only follows its parent)")
            columns.extend(range(start, start + count))
        return columns

    def euler_groups(self, joints: Iterable[str] | None = None) -> list[tuple[str, bool, np.ndarray]]:
        """The joints (all by default) with three rotation channels, grouped by Euler convention
        so that each group converts in one call: (order, extrinsic, columns (joints, 3)), columns
        in the canonical layout.  ASF applies a bone's dofs in their order about fixed axes
        (extrinsic); BVH lists R = R1 R2 R3 (intrinsic, in the listed order)."""
        groups: dict[str, list[list[int]]] = {}
        for joint in self.joint_names if joints is None else joints:
            start, dofs = self.first_column(joint), self.dofs(joint)
            turns = [(start + i, dof) for i, dof in enumerate(dofs) if dof in ROTATIONS]
            if len(turns) == 3:
                groups.setdefault("".join(dof[1] for _, dof in turns), []).append([c for c, _ in turns])
        extrinsic = self.convention != "bvh"
        return [(order, extrinsic, np.array(columns, dtype=np.intp)) for order, columns in groups.items()]

    def rest_positions(self, *, start: bool = False) -> np.ndarray:
        """The calibration pose: (joints, 3) positions in ``joint_names`` order,
        the root at ``:root position`` and each bone's end point (start point
        with ``start=True``), p = p(parent) + direction * length, in file units.
        A BVH skeleton's is the pose its OFFSETs draw: position channels, which
        replace offsets in motion, hold their joint's OFFSET here.  Read-only: it is worked out once."""
        return self.derived(("rest positions", start), lambda: self._rest_positions(start))

    def _rest_positions(self, start: bool) -> np.ndarray:
        tree = self.tree
        values = np.zeros((1, len(self.channels)))
        if self.convention == "bvh":
            for column, (joint, dof) in enumerate(self.channels):
                if dof in TRANSLATIONS:
                    offset = self.root.position if self.is_root(joint) else self.bone(joint).direction
                    values[0, column] = offset[TRANSLATIONS.index(dof)]
        positions = forward_kinematics(values, tree)[0][0]
        positions = positions[np.maximum(tree.parent, 0)] if start else positions
        positions.flags.writeable = False
        return positions

    def sizing(self) -> length_units.Sizing:
        """What the skeleton's size says about its length unit: its extents, up axis and the unit
        that makes the character human-sized (see :func:`motiontheater.model.units.size_up`).  The
        rest pose's, or ``posed`` where a reader found the rest pose no standing pose and sized the
        take's poses instead (:func:`~motiontheater.model.units.size_up_poses`)."""
        return self.posed or self._sizing

    @cached_property
    def _sizing(self) -> length_units.Sizing:
        # every take of a skeleton asks: worked out once
        # CMU's ASFs state their unit: the naming rule is for its BVH conversion
        return length_units.size_up(self.rest_positions(), cmu=self.convention == "bvh" and self.cmu_named)

    @cached_property
    def cmu_named(self) -> bool:
        """Whether the joints are named as CMU's BVH conversion names them (LHipJoint, RHipJoint),
        whose length unit is CMU's inch/0.45."""
        sides = {m.group(1).lower() for b in self.bones if (m := _CMU_HIP.match(b.name))}
        return sides == {"l", "r"}

    def derived(self, key: Hashable, make: Callable[[], T]) -> T:
        """What ``make()`` works out from this skeleton, made once per ``key``: a batch asks for
        the same tables (layouts, column lists) on each of thousands of takes."""
        memo = self.__dict__.setdefault("_derived", {})  # as cached_property keeps its values
        if key not in memo:
            memo[key] = make()
        return memo[key]

    @cached_property
    def tree(self) -> JointTree:
        """The C kernel's tables for this skeleton (see ``mt_forward_kinematics``): joints in
        ``joint_names`` order, worked out once."""
        return _joint_tree(self)

    def unit(self, key: str) -> str | None:
        """The text of a ``:units`` key (``"length"``, ``"angle"``, ``"mass"``), or None."""
        return dict(self.units).get(key)

    @property
    def angle_unit(self) -> str:
        """ "deg" or "rad": the unit of every angle in the skeleton and its motions."""
        unit = (self.unit("angle") or "deg").lower()
        return "rad" if unit.startswith("rad") else "deg"

    @property
    def angle_scale(self) -> float:
        """Radians per angle unit: pi/180 for degrees, 1 for radians."""
        return math.pi / 180 if self.angle_unit == "deg" else 1.0

    @property
    def period(self) -> float:
        """A whole turn in the angle unit: 360 or 2 pi."""
        return 2 * math.pi / self.angle_scale

    @property
    def length_unit(self) -> str | None:
        """The length unit in effect, as text: ``length_choice``'s, else the stated
        ``:units length``; None when there is neither (the Acclaim default, inch)."""
        return self.length_choice[0] if self.length_choice else self.unit("length")

    @property
    def length_source(self) -> str:
        """How the length unit was chosen: "stated" (by the file's ``:units length``),
        "default" (an ASF without one: inch), "detected", "given" or "assumed"
        (see :data:`motiontheater.model.units.SOURCES`)."""
        if self.length_choice:
            return self.length_choice[1]
        return "stated" if self.unit("length") is not None else "default"

    @property
    def meters_per_unit(self) -> float:
        """Metres per file length unit (of :attr:`length_unit`).  A number L is the
        Acclaim convention, file unit = inch / L (CMU and HDM05: L = 0.45)."""
        return length_units.meters_per(self.length_unit or "1")

    def with_length_unit(self, unit: str, source: str = "given") -> Skeleton:
        """The same skeleton (lengths unchanged) read as being in ``unit`` (m, cm, mm, in, or a
        number L for inch / L), chosen as ``source`` says; the stated ``units`` stay as they were."""
        relabelled = replace(self, length_choice=(unit.strip(), source))
        if "tree" in self.__dict__:  # the same geometry: the kinematic tables worked out for the rest pose serve
            relabelled.__dict__["tree"] = self.tree
        return relabelled

    def with_units(
        self, *, length_factor: float = 1.0, length: str | None = None, angle: str | None = None
    ) -> Skeleton:
        """The same skeleton with lengths multiplied by ``length_factor`` (unit text
        ``length``, which then is the unit in effect) and angles converted to ``angle``
        ("deg" or "rad").  A BVH joint's OFFSET (its ``direction``) is a length too."""
        factor = angle_factor(self.angle_unit, angle)
        units = dict(self.units)
        choice = self.length_choice
        if length is not None:
            units["length"] = length
            choice = None  # the stated unit is now the one in effect
        if angle is not None:
            units["angle"] = angle
        bones = tuple(
            replace(
                b,
                length=b.length * length_factor,
                direction=_scaled(b.direction, length_factor) if self.convention == "bvh" else b.direction,
                axis=_scaled(b.axis, factor),
                limits=tuple(
                    (lo * f, hi * f)
                    for (lo, hi), f in zip(b.limits, (factor if d in ROTATIONS else length_factor for d in b.dofs))
                ),
            )
            for b in self.bones
        )
        root = replace(
            self.root,
            position=_scaled(self.root.position, length_factor),
            orientation=_scaled(self.root.orientation, factor),
        )
        posed = self.posed
        if posed is not None and length_factor != 1.0:  # the poses' size scales with the lengths
            extents = tuple(e * length_factor for e in posed.extents)
            told = extents["xyz".index(posed.axis or posed.up)]
            posed = replace(posed, extents=extents, unit=length_units.human_unit(told))  # type: ignore[arg-type]
        return replace(self, bones=bones, root=root, units=tuple(units.items()), length_choice=choice, posed=posed)


def settle_length_unit(skeleton: Skeleton, unit: str | None = None) -> Skeleton:
    """The skeleton with its length unit chosen, as the readers do: ``unit`` when given;
    for a skeleton that states none (a BVH file's), the unit its size tells
    (:func:`motiontheater.model.units.size_up`), else :data:`~motiontheater.model.units.ASSUMED_UNIT`,
    assumed; a stated unit stands unless it makes the character absurdly sized
    (:data:`~motiontheater.model.units.ABSURD_HEIGHT`: an ASF saying ``length m`` of numbers in
    millimetres) and another unit makes it human-sized.  A unit chosen before stays."""
    if unit is not None:
        return skeleton.with_length_unit(unit, "given")
    if skeleton.length_choice is not None:
        return skeleton
    sizing = skeleton.sizing()
    if skeleton.convention == "bvh" and skeleton.unit("length") is None:
        if sizing.unit is None:
            return skeleton.with_length_unit(length_units.ASSUMED_UNIT, "assumed")
        return skeleton.with_length_unit(sizing.unit, "detected")
    if sizing.unit is not None and sizing.absurd(skeleton.meters_per_unit):
        return skeleton.with_length_unit(sizing.unit, "detected")
    return skeleton


def angle_factor(current: str, wanted: str | None) -> float:
    """What angles in ``current`` units are multiplied by to be in ``wanted`` units."""
    if wanted is None or wanted == current:
        return 1.0
    if wanted not in ("deg", "rad"):
        raise ValueError(f"angle unit must be 'deg' or 'rad', got {wanted!r}")
    return math.pi / 180 if wanted == "rad" else 180 / math.pi


def _scaled(v: Vec3, factor: float) -> Vec3:
    return v if factor == 1.0 else (v[0] * factor, v[1] * factor, v[2] * factor)


def _parents_of(hierarchy, index: dict[str, int]) -> dict[str, str]:
    """Each bone's parent; HierarchyError unless the hierarchy is a tree over all bones from the root."""
    parents: dict[str, str] = {}
    for parent, children in hierarchy:
        if parent != "root" and parent not in index:
            raise HierarchyError(f"hierarchy names '{parent}', which is not a bone")
        for child in children:
            if child not in index:
                raise HierarchyError(f"hierarchy names '{child}', which is not a bone")
            if child in parents:
                raise HierarchyError(f"bone '{child}' has two parents, '{parents[child]}' and '{parent}'")
            parents[child] = parent
    reaches = {"root"}  # the bones known to reach the root: each bone is walked once, not once per bone below it
    for name in index:
        if name not in parents:
            raise HierarchyError(f"bone '{name}' has no parent in the hierarchy")
        path, node = set(), name
        while node not in reaches:
            if node in path:
                raise HierarchyError(f"bone '{name}' is in a cycle that does not reach the root")
            path.add(node)
            node = parents[node]
        reaches |= path
    return parents


def canonical_hierarchy(bones: tuple[Bone, ...], pairs) -> tuple[tuple[str, tuple[str, ...]], ...]:
    """(parent, children) pairs, from lines in any order, into Skeleton.hierarchy order."""
    children: dict[str, list[str]] = {}
    for parent, kids in pairs:
        children.setdefault(parent, []).extend(kids)
    order = ["root", *(b.name for b in bones)]
    ordered = [(p, tuple(children.pop(p))) for p in order if p in children]
    # Unknown parents stay, so that Skeleton reports them.
    return tuple(ordered + [(p, tuple(k)) for p, k in children.items()])


def _joint_tree(skeleton: Skeleton) -> JointTree:
    names = skeleton.joint_names
    index = {name: i for i, name in enumerate(names)}
    degrees = skeleton.angle_unit == "deg"
    parent = [-1] + [index[skeleton.parent(b)] for b in skeleton.bone_names]
    order: list[int] = []
    queue = ["root"]
    while queue:  # breadth first from the root: parents before children, whatever the bone order
        name = queue.pop(0)
        order.append(index[name])
        queue.extend(skeleton.children(name))
    root = skeleton.root
    bvh = skeleton.convention == "bvh"
    if bvh:  # a BVH joint's frame is its parent's
        axis = np.concatenate(
            [_axis_frames([(root.axis, root.orientation)], degrees), np.tile(np.eye(3), (len(skeleton.bones), 1, 1))]
        )
    else:
        axis = _axis_frames([(root.axis, root.orientation)] + [(b.axis_order, b.axis) for b in skeleton.bones], degrees)
    direction = [np.zeros(3)]
    segment = [_replaced(root.position, root.order) if bvh else np.asarray(root.position)]
    for bone in skeleton.bones:
        d = np.asarray(bone.direction, float)
        if bvh:  # the OFFSET itself, turned by the parent; position channels replace its components
            direction.append(np.zeros(3))
            segment.append(_replaced(d, bone.dofs))
            continue
        norm = math.hypot(*d)  # no overflow for huge components, unlike the sum of squares
        # no direction: zero; an infinite one (bad input) has none either, and says so with NaN
        unit = d / norm if 0 < norm < math.inf else np.full(3, math.nan if norm else 0.0)
        direction.append(unit)
        # a direction that is already the bone's vector (converted BVH offsets) is kept exactly;
        # an infinite length along no direction (bad input) is NaN, as above, without a warning
        with np.errstate(invalid="ignore"):
            segment.append(d if bone.length == norm else unit * bone.length)
    dof_start, dof_kind, dof_column = [0], [], []  # type: list[int], list[int], list[int]
    column = 0
    for name in names:
        dofs = skeleton.dofs(name)
        entries = [(DOFS[dof], column + i) for i, dof in enumerate(dofs)]
        if bvh:  # BVH lists rotations as R = R1 R2 R3 (v' = R v): about fixed axes, the last applies first
            turns = [e for e in entries if e[0] <= DOFS["rz"]][::-1]
            entries = [e for e in entries if e[0] > DOFS["rz"]] + turns
        for kind, col in entries:
            dof_kind.append(kind)
            dof_column.append(col)
        column += len(dofs)
        dof_start.append(len(dof_kind))
    return JointTree(
        parent=np.array(parent),
        order=np.array(order),
        axis=axis,
        direction=np.array(direction),
        segment=np.array(segment),
        dof_start=np.array(dof_start),
        dof_kind=np.array(dof_kind),
        dof_column=np.array(dof_column),
        angle_scale=skeleton.angle_scale,
        parent_frame=np.array([0] + [1 if bvh else 0] * len(skeleton.bones)),
    )


def _axis_frames(frames: list[tuple[str, Vec3]], degrees: bool) -> np.ndarray:
    """(n, 3, 3): C of each ASF ``axis`` (order, angles): the angles are about x, y and z,
    applied in ``order`` (e.g. "ZYX"); one call per order."""
    out = np.empty((len(frames), 3, 3))
    by_order: dict[str, list[int]] = {}
    for i, (order, _) in enumerate(frames):
        by_order.setdefault(order.upper(), []).append(i)
    for order, rows in by_order.items():
        in_order = [[frames[i][1]["XYZ".index(letter)] for letter in order] for i in rows]
        out[rows] = rotations.euler_to_matrices(in_order, order.lower(), extrinsic=True, degrees=degrees)
    return out


def _replaced(offset: Vec3 | np.ndarray, dofs: tuple[str, ...]) -> np.ndarray:
    """A BVH offset with the components that position channels replace set to zero."""
    out = np.asarray(offset, float).copy()
    for i, dof in enumerate(TRANSLATIONS):
        if dof in dofs:
            out[i] = 0.0
    return out
