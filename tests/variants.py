"""Variants of real takes that other producers' rigs would give: the same motion, laid out as a
game studio, a z-up exporter or a MotionBuilder rig would write it."""

import numpy as np

import motiontheater as mt
from motiontheater.editing.convert import to_bvh
from motiontheater.model.skeleton import TRANSLATIONS, Bone, Root, canonical_hierarchy


def with_static_root(
    motion: mt.Motion, name: str = "Reference", turn=None, shift=(0.0, 0.0, 0.0), *, keep_world: bool = True
) -> mt.Motion:
    """A BVH take under a joint above its root that never moves (six channels, constant): at
    ``shift``, turned by ``turn`` (X, Y, Z rotation channels in degrees; None: not turned, and then
    the old root's channels are exactly the same numbers).  ``keep_world``: the old root's channels
    are made relative to the static joint, so that every point stays where it was; else they stay
    as they were and the whole take turns and moves with the static joint (``turn=(90, 0, 0)``:
    a y-up take stands along z, as a z-up exporter writes it).  An ASF/AMC take is made BVH
    first (:func:`to_bvh`): its bones' axes are no BVH joint's."""
    motion = to_bvh(motion)
    skeleton = motion.skeleton
    old = skeleton.root
    turn = (0.0, 0.0, 0.0) if turn is None else turn
    values = motion.values
    if keep_world and (any(turn) or any(shift)):  # the old root's channels, in the static joint's frame
        from motiontheater.model.rig import _local, _through

        static = _local(("tx", "ty", "tz", "rx", "ry", "rz"), np.array([[*shift, *turn]]), (0, 0, 0))[0]
        values = values.copy()
        root_columns = len(old.order)
        values[:, :root_columns] = _through(values[:, :root_columns], old.order, np.linalg.inv(static))
    body = old.name if old.name != "root" else "Hips"  # a joint may not be called root
    hips = Bone(body, direction=old.position, length=float(np.linalg.norm(old.position)), dofs=old.order)
    bones = (hips, *skeleton.bones)
    pairs = [("root", (body,))] + [(body if p == "root" else p, children) for p, children in skeleton.hierarchy]
    new = mt.Skeleton(
        bones=bones,
        hierarchy=canonical_hierarchy(bones, pairs),
        root=Root(order=("tx", "ty", "tz", "rx", "ry", "rz"), position=(0.0, 0.0, 0.0), name=name),
        name=skeleton.name,
        units=skeleton.units,
        convention="bvh",
        length_choice=skeleton.length_choice,
    )
    static_columns = np.tile([*shift, *turn], (motion.frames, 1))
    values = np.concatenate([static_columns, values], axis=1)
    values.flags.writeable = False
    return mt.Motion(new, values, frame_rate=motion.frame_rate, first_frame=motion.first_frame, header=motion.header)


def with_offset_channels(motion: mt.Motion) -> mt.Motion:
    """A BVH take with position channels on every joint (not the end sites) that hold its OFFSET in
    every frame, as LAFAN-style and many MotionBuilder exports write them (an ASF/AMC take made
    BVH first)."""
    motion = to_bvh(motion)
    skeleton = motion.skeleton
    bones, columns = [], [motion.values[:, motion.columns("root")]]
    for bone in skeleton.bones:
        if bone.end_site:
            bones.append(bone)
            continue
        missing = tuple(d for d in TRANSLATIONS if d not in bone.dofs)
        bones.append(Bone(bone.name, bone.direction, bone.length, dofs=missing + bone.dofs, end_site=False))
        columns.append(np.tile([bone.direction[TRANSLATIONS.index(d)] for d in missing], (motion.frames, 1)))
        columns.append(motion.values[:, motion.columns(bone.name)])
    new = mt.Skeleton(
        bones=tuple(bones),
        hierarchy=skeleton.hierarchy,
        root=skeleton.root,
        name=skeleton.name,
        units=skeleton.units,
        convention="bvh",
        length_choice=skeleton.length_choice,
    )
    values = np.concatenate([c.reshape(motion.frames, -1) for c in columns], axis=1)
    values.flags.writeable = False
    return mt.Motion(new, values, frame_rate=motion.frame_rate, first_frame=motion.first_frame, header=motion.header)
