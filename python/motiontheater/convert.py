"""ASF/AMC <-> BVH: the same motion in the other format, forward kinematics giving the same points.

ASF bones turn their own segment; BVH joints turn their children's
offsets.  So an ASF bone becomes a BVH joint at the bone's start, carrying
the bone's local rotation C M C^T as Euler angles, with the bone's vector
as the offset of the joints (or End Site) at its end.  A BVH segment from a
joint to a child becomes an ASF bone named after the child, carrying the
joint's rotation channels (in ASF's order: BVH lists R = R1 R2 R3, ASF
applies dofs about fixed axes, so the list is reversed) with an identity
axis.  Angles are degrees in BVH; lengths keep their units.
"""

from __future__ import annotations

from typing import Annotated, Literal

import numpy as np

from mtcore.kinematics import forward_kinematics
from mtcore.rotations import matrices_to_euler

from .motion import Motion
from .registry import step
from .skeleton import ROTATIONS, TRANSLATIONS, Bone, Root, Skeleton, canonical_hierarchy

BVH_ORDERS = ("XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX")


def to_bvh(motion: Motion, order: str = "ZXY") -> Motion:
    """An ASF/AMC motion as a BVH motion (rotation channels listed in ``order``, e.g. "ZXY")."""
    skeleton = motion.skeleton
    if skeleton.convention == "bvh":
        return motion
    order = order.upper()
    if order not in BVH_ORDERS:
        raise ValueError(f"order must be one of {', '.join(BVH_ORDERS)}, got {order!r}")
    for bone in skeleton.bones:
        if set(bone.dofs) - set(ROTATIONS):
            raise ValueError(
                f"bone '{bone.name}' has translation dofs {bone.dofs}: BVH conversion supports rotation dofs only"
            )
    rotation_dofs = tuple("r" + a.lower() for a in order)
    fixed = order[::-1].lower()  # BVH's R = R1 R2 R3 applies R3 first about fixed axes
    tree = skeleton.tree
    segments = dict(zip(skeleton.bone_names, tree.segment[1:]))
    bones, pairs = [], []
    for bone in skeleton.bones:
        parent = skeleton.parent(bone.name)
        offset = segments[parent] if parent != "root" else np.zeros(3)
        turns = bool(bone.dofs)
        bones.append(
            Bone(
                name=bone.name,
                direction=tuple(offset),
                length=float(np.linalg.norm(offset)),
                dofs=rotation_dofs if turns else (),
            )
        )
        pairs.append((parent, (bone.name,)))
        if not skeleton.children(bone.name):
            bones.append(
                Bone(
                    name=f"{bone.name}_End",
                    direction=tuple(segments[bone.name]),
                    length=float(np.linalg.norm(segments[bone.name])),
                    end_site=True,
                )
            )
            pairs.append((bone.name, (f"{bone.name}_End",)))
    root = Root(order=("tx", "ty", "tz", *rotation_dofs), position=(0.0, 0.0, 0.0), name="root")
    target = Skeleton(
        bones=tuple(bones),
        hierarchy=canonical_hierarchy(tuple(bones), pairs),
        root=root,
        name=skeleton.name,
        units=(("angle", "deg"),),
        convention="bvh",
    )
    positions, _, local = forward_kinematics(motion.values, tree, local=True)
    assert local is not None  # asked for
    turning = [j for j, name in enumerate(skeleton.joint_names) if name == "root" or skeleton.bone(name).dofs]
    angles = np.degrees(matrices_to_euler(local[:, turning], fixed, extrinsic=True))[..., ::-1]  # in the listed order
    values = np.concatenate([positions[:, 0], angles.reshape(motion.frames, 3 * len(turning))], axis=1)
    values.flags.writeable = False
    return Motion(target, values, frame_rate=motion.frame_rate, first_frame=motion.first_frame, header=())


def to_asf(motion: Motion) -> Motion:
    """A BVH motion as an ASF/AMC motion (bones named after the joints they end at)."""
    skeleton = motion.skeleton
    if skeleton.convention != "bvh":
        return motion
    for bone in skeleton.bones:
        if set(bone.dofs) - set(ROTATIONS):
            raise ValueError(
                f"joint '{bone.name}' has position channels: ASF conversion supports them on the root only"
            )
    root = skeleton.root
    root_rotations = tuple(d for d in root.order if d in ROTATIONS)[::-1]
    root_translations = tuple(d for d in root.order if d in TRANSLATIONS)
    x, y, z = (0.0 if d in root_translations else v for d, v in zip(TRANSLATIONS, root.position))
    bones, pairs = [], []
    for bone in skeleton.bones:
        parent = skeleton.parent(bone.name)
        turner = () if parent == "root" else tuple(d for d in skeleton.bone(parent).dofs)[::-1]
        name = bone.name.replace(" ", "_")
        bones.append(
            Bone(
                name=name,
                direction=bone.direction,
                length=float(np.linalg.norm(bone.direction)),
                dofs=turner,
                axis=(0.0, 0.0, 0.0),
                axis_order="XYZ",
            )
        )
        pairs.append(("root" if parent == "root" else parent.replace(" ", "_"), (name,)))
    target = Skeleton(
        bones=tuple(bones),
        hierarchy=canonical_hierarchy(tuple(bones), pairs),
        root=Root(order=(*root_translations, *root_rotations), position=(x, y, z)),
        name=skeleton.name or "converted",
        units=(("mass", "1.0"), ("length", "1.0"), ("angle", "deg")),
    )
    columns = [motion.values[:, motion.columns("root", root_translations)]] if root_translations else []
    columns.append(
        motion.values[:, motion.columns("root", root_rotations)] if root_rotations else np.zeros((motion.frames, 0))
    )
    for bone in skeleton.bones:
        parent = skeleton.parent(bone.name)
        if parent != "root" and skeleton.bone(parent).dofs:
            columns.append(motion.values[:, motion.columns(parent, skeleton.bone(parent).dofs[::-1])])
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

    ASF/AMC to BVH: a joint at each bone's start carries the bone's rotation.
    BVH to ASF/AMC: a bone per segment, named after the joint it ends at; the
    skeleton is written beside an AMC output as OUT.asf.
    """
    if to is None:
        to = "asf" if motion.skeleton.convention == "bvh" else "bvh"
    return to_bvh(motion, order) if to == "bvh" else to_asf(motion)
