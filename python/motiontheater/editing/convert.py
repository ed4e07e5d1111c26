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

A BVH segment from a joint to a child becomes an ASF bone named after the
child, carrying the joint's rotation channels (in ASF's order: BVH lists
R = R1 R2 R3, ASF applies dofs about fixed axes, so the list is reversed)
with an identity axis and the child's OFFSET as its vector.  The child's
position channels, which replace its OFFSET, become translation dofs of
that bone holding the change from the OFFSET (zero where a file repeats
its offsets in every frame, as Bandai Namco's dataset does), so that the
ASF's rest pose is the BVH's; every other value is copied unchanged.  Angles are degrees in BVH.  Lengths keep their
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
    bones, pairs = [], []
    columns = [positions[:, 0], angles.get("root", np.zeros((motion.frames, 3)))]
    for bone in skeleton.bones:
        parent = skeleton.parent(bone.name)
        turns = bone.name in angles
        carried = parent in reach
        offset = segment[parent] if parent != "root" else np.zeros(3)
        held = not carried and not turns  # no channel: three rotations held at zero, as CMU's conversion writes
        dofs = (TRANSLATIONS if carried else ()) + (rotation_dofs if turns or held else ())
        bones.append(_bvh_bone(bone.name, offset, dofs))
        pairs.append((parent, (bone.name,)))
        if carried:
            columns.append(reach[parent])
        if turns:
            columns.append(angles[bone.name])
        elif held:
            columns.append(np.zeros((motion.frames, 3)))
        if skeleton.children(bone.name):
            continue
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
    root = Root(order=("tx", "ty", "tz", *rotation_dofs), position=(0.0, 0.0, 0.0), name="root")
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


def to_asf(motion: Motion) -> Motion:
    """A BVH motion as an ASF/AMC motion (bones named after the joints they end at, spaces as "_").

    Position channels on any joint become translation dofs of the bone ending
    there, holding the change from the joint's OFFSET (the bone's rest vector);
    other values are copied unchanged.  The BVH's length unit (detected,
    given or assumed) becomes the ASF's ``:units length``."""
    skeleton = motion.skeleton
    if skeleton.convention != "bvh":
        return motion
    root = skeleton.root
    root_rotations = tuple(d for d in root.order if d in ROTATIONS)[::-1]
    root_translations = tuple(d for d in root.order if d in TRANSLATIONS)
    x, y, z = (0.0 if d in root.order else float(v) for d, v in zip(TRANSLATIONS, root.position))
    bones, pairs = [], []
    columns = [motion.values[:, motion.columns("root", root_translations + root_rotations)]]
    for bone in skeleton.bones:
        parent = skeleton.parent(bone.name)
        turner = () if parent == "root" else tuple(d for d in skeleton.bone(parent).dofs if d in ROTATIONS)[::-1]
        shift = tuple(d for d in bone.dofs if d in TRANSLATIONS)
        name = bone.name.replace(" ", "_")
        length = math.hypot(*bone.direction)  # as the kinematic tables measure it: the vector is kept exactly
        bones.append(Bone(name=name, direction=bone.direction, length=length, dofs=turner + shift))
        pairs.append(("root" if parent == "root" else parent.replace(" ", "_"), (name,)))
        if turner:
            columns.append(motion.values[:, motion.columns(parent, turner)])
        if shift:  # the change from the OFFSET, which stays the bone's rest vector
            rest = np.array([bone.direction[TRANSLATIONS.index(d)] for d in shift])
            columns.append(motion.values[:, motion.columns(bone.name, shift)] - rest)
    stated = dict(skeleton.units)
    unit = stated.pop("length", skeleton.length_unit)
    units = {"mass": stated.pop("mass", "1.0"), **({"length": unit} if unit else {}), "angle": "deg"}
    stated.pop("angle", None)
    target = Skeleton(
        bones=tuple(bones),
        hierarchy=canonical_hierarchy(tuple(bones), pairs),
        root=Root(order=root_translations + root_rotations, position=(x, y, z)),
        name=skeleton.name or "converted",
        units=tuple({**units, **stated}.items()),
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


@step(
    "convert", "turn an ASF/AMC motion into a BVH one or back (forward kinematics gives the same points)", frames="none"
)
def convert(
    motion: Motion,
    *,
    to: Annotated[Literal["bvh", "asf"] | None, "the convention to convert to (default: the other one)"] = None,
    order: Annotated[Literal["ZXY", "XYZ", "XZY", "YXZ", "YZX", "ZYX"], "rotation channel order of BVH joints"] = "ZXY",
) -> Motion:
    """The motion in the other file convention: see :func:`to_bvh` and :func:`to_asf`.

    ASF/AMC to BVH: a joint at each bone's start carries the bone's rotation
    (and position channels where the bone before translates or stretches).
    BVH to ASF/AMC: a bone per segment, named after the joint it ends at, with
    translation dofs where the joint has position channels; the skeleton is
    written beside an AMC output as OUT.asf.  Lengths keep their numbers and
    their unit: the ASF's :units length goes with the BVH motion, and a BVH's
    (detected, given with --unit, or assumed) becomes the ASF's.  A BVH file
    states no unit: one whose size does not tell it is read back with --unit.
    """
    if to is None:
        to = "asf" if motion.skeleton.convention == "bvh" else "bvh"
    return to_bvh(motion, order) if to == "bvh" else to_asf(motion)
