"""Skeletons: the bones of an ASF file, their rest pose and hierarchy."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from mtcore.errors import DuplicateError, HierarchyError, UnknownNameError

Vec3 = tuple[float, float, float]

ROTATIONS = ("rx", "ry", "rz")
TRANSLATIONS = ("tx", "ty", "tz")
BONE_DOFS = (*ROTATIONS, *TRANSLATIONS, "l")  # "l": translation along the bone (stretch)
ROOT_DOFS = (*TRANSLATIONS, *ROTATIONS)

# Length units by name; a number L means the Acclaim convention: file unit = inch / L.
_METERS_PER_NAMED_UNIT = {
    "m": 1.0,
    "meter": 1.0,
    "meters": 1.0,
    "metre": 1.0,
    "metres": 1.0,
    "cm": 0.01,
    "mm": 0.001,
    "in": 0.0254,
    "inch": 0.0254,
    "inches": 0.0254,
}


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
        channels, first = [], {}
        for joint in ("root", *(b.name for b in self.bones)):
            first[joint] = len(channels)
            channels.extend((joint, d) for d in (self.root.order if joint == "root" else self.bone(joint).dofs))
        object.__setattr__(self, "_channels", tuple(channels))
        object.__setattr__(self, "_first_column", first)

    @property
    def bone_names(self) -> tuple[str, ...]:
        """The bones in ``:bonedata`` order."""
        return tuple(b.name for b in self.bones)

    @property
    def joint_names(self) -> tuple[str, ...]:
        """The root followed by the bones in ``:bonedata`` order; the root is called "root"."""
        return ("root", *self.bone_names)

    @property
    def point_names(self) -> tuple[str, ...]:
        """``joint_names`` with the root under its own name (a BVH file's, e.g. "Hips"): what
        exported positions are called."""
        return (self.root.name, *self.bone_names)

    def bone(self, name: str) -> Bone:
        try:
            return self.bones[self._index[name]]
        except KeyError:
            raise UnknownNameError(f"no bone '{name}' in skeleton '{self.name}'") from None

    def parent(self, name: str) -> str:
        """The parent of bone ``name`` ("root" for the root's children)."""
        self.bone(name)
        return self._parents[name]

    def children(self, name: str) -> tuple[str, ...]:
        return self._children.get(name, ())

    def dofs(self, joint: str) -> tuple[str, ...]:
        """The channels of a joint ("root" or a bone name), in file order."""
        return self.root.order if joint == "root" else self.bone(joint).dofs

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

    def rest_positions(self, *, start: bool = False) -> np.ndarray:
        """The calibration pose: (joints, 3) positions in ``joint_names`` order,
        the root at ``:root position`` and each bone's end point (start point
        with ``start=True``), p = p(parent) + direction * length, in file units."""
        from mtcore.kinematics import forward_kinematics  # kinematics builds on this module

        from .kinematics import joint_tree

        tree = joint_tree(self)
        positions = forward_kinematics(np.zeros((1, len(self.channels))), tree)[0][0]
        return positions[np.maximum(tree.parent, 0)] if start else positions

    def unit(self, key: str) -> str | None:
        return dict(self.units).get(key)

    @property
    def angle_unit(self) -> str:
        """ "deg" or "rad": the unit of every angle in the skeleton and its motions."""
        unit = (self.unit("angle") or "deg").lower()
        return "rad" if unit.startswith("rad") else "deg"

    @property
    def meters_per_unit(self) -> float:
        """Metres per file length unit.  A number L under ``:units length`` is the
        Acclaim convention, file unit = inch / L (CMU and HDM05: L = 0.45)."""
        text = (self.unit("length") or "1").strip().lower()
        if text in _METERS_PER_NAMED_UNIT:
            return _METERS_PER_NAMED_UNIT[text]
        try:
            return 0.0254 / float(text)
        except (ValueError, ZeroDivisionError):
            raise ValueError(f"unknown length unit '{text}'") from None

    def with_units(
        self, *, length_factor: float = 1.0, length: str | None = None, angle: str | None = None
    ) -> Skeleton:
        """The same skeleton with lengths multiplied by ``length_factor`` (unit text
        ``length``) and angles converted to ``angle`` ("deg" or "rad")."""
        angle_factor = _angle_factor(self.angle_unit, angle)
        units = dict(self.units)
        if length is not None:
            units["length"] = length
        if angle is not None:
            units["angle"] = angle
        bones = tuple(
            replace(
                b,
                length=b.length * length_factor,
                axis=_scaled(b.axis, angle_factor),
                limits=tuple(
                    (lo * f, hi * f)
                    for (lo, hi), f in zip(
                        b.limits, (angle_factor if d in ROTATIONS else length_factor for d in b.dofs)
                    )
                ),
            )
            for b in self.bones
        )
        root = replace(
            self.root,
            position=_scaled(self.root.position, length_factor),
            orientation=_scaled(self.root.orientation, angle_factor),
        )
        return replace(self, bones=bones, root=root, units=tuple(units.items()))


def _angle_factor(current: str, wanted: str | None) -> float:
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
    for name in index:
        if name not in parents:
            raise HierarchyError(f"bone '{name}' has no parent in the hierarchy")
        seen, node = set(), name
        while node != "root":
            if node in seen:
                raise HierarchyError(f"bone '{name}' is in a cycle that does not reach the root")
            seen.add(node)
            node = parents[node]
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
