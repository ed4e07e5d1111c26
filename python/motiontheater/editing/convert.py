"""ASF/AMC <-> BVH: the same motion in the other format, forward kinematics giving the same points.

ASF bones turn their own segment; BVH joints turn their children's
offsets.  So an ASF bone becomes a BVH joint at the bone's start, carrying
the bone's local rotation C M C^T as Euler angles, with the bone's vector
as the offset of the joints (or End Site) at its end.  A bone with
translation (tx ty tz) or stretch (l) dofs reaches its end by
segment + direction l + C t, which changes over frames: the joints at its
end carry that vector as position channels (which replace a BVH offset),
and a leaf's end becomes a joint ``<bone>_End`` with position channels and
an End Site.

A BVH joint becomes the ASF bone of its name, from the joint to its first
child, carrying the joint's rotation channels (in ASF's order: BVH lists
R = R1 R2 R3, ASF applies dofs about fixed axes, so the list is reversed)
with an identity axis and the child's OFFSET as its vector.  ASF bones
start where their parent ends, so a child elsewhere (the hips below the
root, the shoulders beside the neck) is reached by a dof-less bone
``<joint>_to_<child>``.  Position channels, which replace a joint's
OFFSET, become translation dofs of the bone that ends there, holding the
change from the OFFSET (zero where a file repeats its offsets in every
frame, as Bandai Namco's dataset does), so that the ASF's rest pose is
the BVH's; every other value is copied unchanged.  The ASF's
:documentation names the BVH root and the reaching bones, so that BVH ->
ASF -> BVH gives the same joints, names and points, as AMC -> BVH -> AMC
gives the same bones.  Angles are degrees in BVH.  Lengths keep their
numbers and their unit: the ASF's ``:units length`` text (0.45 for CMU and
HDM05) goes with the motion both ways, and a BVH's detected or given unit
becomes the ASF's ``:units length``.
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

import numpy as np

from mtcore.kinematics import forward_kinematics
from mtcore.rotations import matrices_to_euler

from ..model.motion import Motion
from ..model.registry import step
from ..model.skeleton import ROTATIONS, TRANSLATIONS, Bone, Root, Skeleton, canonical_hierarchy

BVH_ORDERS = ("XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX")
_MOVES = {*TRANSLATIONS, "l"}  # the dofs that move a bone's end along or across it


def to_bvh(motion: Motion, order: str = "ZXY") -> Motion:
    """An ASF/AMC motion as a BVH motion (rotation channels listed in ``order``, e.g. "ZXY").

    Every joint of the ASF skeleton is at the same point in every frame (to
    rounding); the BVH joint named after a bone is at the bone's start, the
    bone's end is its first child joint or the End Site (or, for a bone with
    translation or stretch dofs, the joint) ``<bone>_End``.  A bone without
    dofs (CMU's ``lhipjoint``) becomes a joint of three rotation channels held
    at zero, as CMU's own BVH conversion writes it: BVH readers refuse
    ``CHANNELS 0``.  The units (``:units length``, e.g. 0.45) go with it;
    angles become degrees."""
    skeleton = motion.skeleton
    if skeleton.convention == "bvh":
        return motion
    order = order.upper()
    if order not in BVH_ORDERS:
        raise ValueError(f"order must be one of {', '.join(BVH_ORDERS)}, got {order!r}")
    rotation_dofs = tuple("r" + a.lower() for a in order)
    fixed = order[::-1].lower()  # BVH's R = R1 R2 R3 applies R3 first about fixed axes
    tree = skeleton.tree
    names = skeleton.joint_names
    positions, _, local = forward_kinematics(motion.values, tree, local=True)
    assert local is not None  # asked for
    turning = [j for j, name in enumerate(names) if set(skeleton.dofs(name)) & set(ROTATIONS)]
    euler = np.degrees(matrices_to_euler(local[:, turning], fixed, extrinsic=True))[..., ::-1]  # as listed
    angles = {names[j]: euler[:, i] for i, j in enumerate(turning)}
    reach = {b.name: _reach(motion, j + 1) for j, b in enumerate(skeleton.bones) if _MOVES & set(b.dofs)}
    segment = dict(zip(names, tree.segment))
    root_name, connectors, bare = _notes(skeleton)
    bones: list[Bone] = []
    pairs: list[tuple[str, tuple[str, ...]]] = []
    columns = [positions[:, 0], angles.get("root", np.zeros((motion.frames, 3)))]
    for bone in skeleton.bones:
        if bone.name in connectors:
            continue  # a bone that only reaches the joint after it: that joint hangs from its parent
        parent = skeleton.parent(bone.name)
        via = [parent] if parent in connectors else []
        if via:
            parent = skeleton.parent(parent)
        turns = bone.name in angles
        steps = ([parent] if parent != "root" else []) + via  # from the parent joint to this one
        carried = any(step in reach for step in steps)
        offset = sum((segment[step] for step in steps), np.zeros(3))
        held = not carried and not turns  # no channel: three rotations held at zero, as CMU's conversion writes
        dofs = (TRANSLATIONS if carried else ()) + (rotation_dofs if turns or held else ())
        bones.append(_bvh_bone(bone.name, offset, dofs))
        pairs.append((parent, (bone.name,)))
        if carried:
            columns.append(sum((reach[step] if step in reach else segment[step] for step in steps), np.zeros(3)))
        if turns:
            columns.append(angles[bone.name])
        elif held:
            columns.append(np.zeros((motion.frames, 3)))
        if any(c not in connectors for c in skeleton.children(bone.name)):
            continue  # a joint starts where the bone ends: no End Site there
        if bone.name in bare:
            continue  # a BVH leaf joint without an End Site, as it was
        end = f"{bone.name}_End"
        pairs.append((bone.name, (end,)))
        if bone.name in reach:  # the end moves: a joint of position channels, then an End Site on it
            bones += [
                _bvh_bone(end, segment[bone.name], TRANSLATIONS),
                _bvh_bone(f"{end}_End", (0, 0, 0), end_site=True),
            ]
            pairs.append((end, (f"{end}_End",)))
            columns.append(reach[bone.name])
        else:
            bones.append(_bvh_bone(end, segment[bone.name], end_site=True))
    root = Root(order=("tx", "ty", "tz", *rotation_dofs), position=(0.0, 0.0, 0.0), name=root_name)
    units = dict(skeleton.units)
    units["angle"] = "deg"
    target = Skeleton(
        bones=tuple(bones),
        hierarchy=canonical_hierarchy(tuple(bones), pairs),
        root=root,
        name=skeleton.name,
        units=tuple(units.items()),
        convention="bvh",
        length_choice=skeleton.length_choice,
    )
    values = np.concatenate([c.reshape(motion.frames, -1) for c in columns], axis=1)
    values.flags.writeable = False
    return Motion(target, values, frame_rate=motion.frame_rate, first_frame=motion.first_frame, header=())


def _reach(motion: Motion, joint: int) -> np.ndarray:
    """(frames, 3): the vector from an ASF bone's start to its end in its own frame per frame,
    segment + direction l + C t (joint: its index in ``joint_names``)."""
    skeleton, tree = motion.skeleton, motion.skeleton.tree
    name = skeleton.joint_names[joint]
    shift = np.zeros((motion.frames, 3))
    stretch = np.zeros(motion.frames)
    for column, dof in zip(motion.columns(name), skeleton.dofs(name)):
        if dof in TRANSLATIONS:
            shift[:, TRANSLATIONS.index(dof)] += motion.values[:, column]
        elif dof == "l":
            stretch += motion.values[:, column]
    return tree.segment[joint] + stretch[:, None] * tree.direction[joint] + shift @ tree.axis[joint].T


def _bvh_bone(name: str, offset, dofs: tuple[str, ...] = (), *, end_site: bool = False) -> Bone:
    """A BVH joint, or End Site, at ``offset`` from its parent."""
    x, y, z = (float(v) for v in offset)
    return Bone(name=name, direction=(x, y, z), length=math.hypot(x, y, z), dofs=dofs, end_site=end_site)


ROOT_NOTE = "motiontheater: the BVH root is called "
CONNECTORS_NOTE = "motiontheater: bones that only reach the joint after them: "
BARE_NOTE = "motiontheater: joints that end without an End Site: "
"""Lines of an ASF's :documentation that to_asf writes and to_bvh reads, so that a BVH goes
through ASF/AMC and back with its joints, names and points."""


def to_asf(motion: Motion) -> Motion:
    """A BVH motion as an ASF/AMC motion: each joint a bone of the same name (spaces as "_"),
    from the joint to its first child, turned by the joint's rotation channels.

    ASF bones start where their parent ends, so a child that sits elsewhere (the hips below
    the root, the shoulders beside the neck) is reached by a bone of its own without dofs,
    ``<joint>_to_<child>``; End Sites are the ends of their joints' bones.  Position channels
    become translation dofs of the bone that ends at the joint, holding the change from the
    joint's OFFSET (zero where a file repeats its offsets in every frame); every other value is
    copied unchanged.  The ASF's :documentation names the root and the reaching bones, so that
    :func:`to_bvh` gives the BVH's joints, names and points back.  The BVH's length unit
    (detected, given or assumed) becomes the ASF's ``:units length``."""
    skeleton = motion.skeleton
    if skeleton.convention != "bvh":
        return motion
    root = skeleton.root
    root_rotations = tuple(d for d in root.order if d in ROTATIONS)[::-1]
    root_translations = tuple(d for d in root.order if d in TRANSLATIONS)
    x, y, z = (0.0 if d in root.order else float(v) for d, v in zip(TRANSLATIONS, root.position))
    name = {j: j.replace(" ", "_") for j in skeleton.bone_names}
    bones: list[Bone] = []
    pairs: list[tuple[str, tuple[str, ...]]] = []
    columns = [motion.values[:, motion.columns("root", root_translations + root_rotations)]]
    connectors: list[str] = []
    end_of = {"root": "root"}  # each BVH joint: the ASF bone (or root) that ends where it is

    def offset(joint: str) -> np.ndarray:
        return np.array(skeleton.bone(joint).direction)

    def shift(joint: str, minus: np.ndarray | None) -> tuple[tuple[str, ...], np.ndarray | None]:
        """A joint's position channels as the change from its OFFSET (less ``minus``, the shift of
        the bone end they hang from): (dofs, values), or ((), None) where there is nothing."""
        dofs = tuple(d for d in skeleton.dofs(joint) if d in TRANSLATIONS) if joint != "root" else ()
        if minus is not None and dofs != TRANSLATIONS:
            dofs = TRANSLATIONS
        if not dofs:
            return (), None
        values = np.zeros((motion.frames, 3))
        for d, c in zip(skeleton.dofs(joint), motion.columns(joint)):
            if d in TRANSLATIONS:
                values[:, TRANSLATIONS.index(d)] = motion.values[:, c] - offset(joint)[TRANSLATIONS.index(d)]
        if minus is not None:
            values = values - minus
        return dofs, values[:, [TRANSLATIONS.index(d) for d in dofs]]

    def add(bone: Bone, parent: str, values: list[np.ndarray]) -> None:
        bones.append(bone)
        pairs.append((parent, (bone.name,)))
        columns.extend(values)

    order, todo = [], ["root"]  # parents before children, whatever order the bones are listed in
    while todo:
        order.append(todo.pop())
        todo.extend(c for c in reversed(skeleton.children(order[-1])) if not skeleton.bone(c).end_site)
    for joint in order:
        children = skeleton.children(joint)
        start = end_of[joint]
        primary: str | None = None
        base = np.zeros(3)
        moved: np.ndarray | None = None  # the shift of the bone end the other children hang from
        if joint != "root":
            turner = tuple(d for d in skeleton.dofs(joint) if d in ROTATIONS)[::-1]
            joints = [c for c in children if not skeleton.bone(c).end_site]
            primary = (joints or list(children))[0] if children else None
            direction = offset(primary) if primary is not None else np.zeros(3)
            shift_dofs, shift_values = shift(primary, None) if primary is not None else ((), None)
            carried = [motion.values[:, motion.columns(joint, turner)]] if turner else []
            if shift_values is not None:
                carried.append(shift_values)
                moved = np.zeros((motion.frames, 3))
                moved[:, [TRANSLATIONS.index(d) for d in shift_dofs]] = shift_values
            add(_asf_bone(name[joint], direction, turner + shift_dofs), start, carried)
            base = direction
            if primary is not None:
                end_of[primary] = name[joint]
        for child in children:
            if child == primary:
                continue
            dofs, shifted = shift(child, moved)
            if shifted is None and np.array_equal(offset(child), base):
                end_of[child] = start if joint == "root" else name[joint]  # it starts where the bone ends
                continue
            reach = f"{root.name if joint == 'root' else name[joint]}_to_{name[child]}".replace(" ", "_")
            add(_asf_bone(reach, offset(child) - base, dofs), start if joint == "root" else name[joint], [])
            if shifted is not None:
                columns.append(shifted)
            connectors.append(reach)
            end_of[child] = reach
    stated = dict(skeleton.units)
    unit = stated.pop("length", skeleton.length_unit)
    units = {"mass": stated.pop("mass", "1.0"), **({"length": unit} if unit else {}), "angle": "deg"}
    stated.pop("angle", None)
    bare = [name[j] for j in order if j != "root" and not skeleton.children(j)]
    notes = (
        ((ROOT_NOTE + root.name,) if root.name != "root" else ())
        + ((CONNECTORS_NOTE + " ".join(connectors),) if connectors else ())
        + ((BARE_NOTE + " ".join(bare),) if bare else ())
    )
    target = Skeleton(
        bones=tuple(bones),
        hierarchy=canonical_hierarchy(tuple(bones), pairs),
        root=Root(order=root_translations + root_rotations, position=(x, y, z)),
        name=skeleton.name or "converted",
        units=tuple({**units, **stated}.items()),
        documentation=notes,
        length_choice=skeleton.length_choice,
    )
    values = np.concatenate(columns, axis=1)
    values.flags.writeable = False
    return Motion(
        target,
        values,
        frame_rate=motion.frame_rate,
        first_frame=motion.first_frame,
        header=(":FULLY-SPECIFIED", ":DEGREES"),
    )


def _asf_bone(name: str, direction, dofs: tuple[str, ...]) -> Bone:
    x, y, z = (float(v) for v in direction)
    return Bone(name=name, direction=(x, y, z), length=math.hypot(x, y, z), dofs=dofs)


def _notes(skeleton: Skeleton) -> tuple[str, frozenset[str], frozenset[str]]:
    """What to_asf wrote into an ASF's :documentation: the BVH root's name, the reaching bones,
    the leaf joints that had no End Site."""
    root, connectors, bare = "root", frozenset[str](), frozenset[str]()
    for line in skeleton.documentation:
        text = line.strip()
        if text.startswith(ROOT_NOTE):
            root = text[len(ROOT_NOTE) :].strip() or "root"
        elif text.startswith(CONNECTORS_NOTE):
            connectors = frozenset(text[len(CONNECTORS_NOTE) :].split())
        elif text.startswith(BARE_NOTE):
            bare = frozenset(text[len(BARE_NOTE) :].split())
    return root, connectors, bare


@step(
    "convert",
    "turn an ASF/AMC motion into a BVH one or back (forward kinematics gives the same points)",
    frames="none",
    convention=lambda convention, options: options["to"] or ("asf" if convention == "bvh" else "bvh"),
)
def convert(
    motion: Motion,
    *,
    to: Annotated[
        Literal["bvh", "asf"] | None,
        "the convention to convert to (default: the other one; on the command line, the output's)",
    ] = None,
    order: Annotated[Literal["ZXY", "XYZ", "XZY", "YXZ", "YZX", "ZYX"], "rotation channel order of BVH joints"] = "ZXY",
) -> Motion:
    """The motion in the other file convention: see :func:`to_bvh` and :func:`to_asf`.

    ASF/AMC to BVH: a joint at each bone's start carries the bone's rotation
    (and position channels where the bone before translates or stretches).
    BVH to ASF/AMC: a bone per joint, of its name, from the joint to its
    first child, and a dof-less bone JOINT_to_CHILD to reach a child that
    sits elsewhere; translation dofs where a joint has position channels.
    Either way and back gives the same joints, names and points.  The
    skeleton is written beside an AMC output as OUT.asf.  Lengths keep their numbers and
    their unit: the ASF's :units length goes with the BVH motion, and a BVH's
    (detected, given with --unit, or assumed) becomes the ASF's.  A BVH file
    states no unit: one whose size does not tell it is read back with --unit.
    """
    if to is None:
        to = "asf" if motion.skeleton.convention == "bvh" else "bvh"
    return to_bvh(motion, order) if to == "bvh" else to_asf(motion)
