"""Twins of mt_forward_kinematics in vectorised numpy: from a JointTree (the kernel's own input),
and from a motion's skeleton (which checks the tree motiontheater builds as well)."""

from __future__ import annotations

import numpy as np

from .rotations import axis_matrices, matrices, matrices_to_quaternions, unroll_quaternions

RX, RZ, TX, TZ = 0, 2, 3, 5  # mt_dof codes


def forward_kinematics(values, tree) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(positions (frames, joints, 3), world, local (frames, joints, 3, 3)) as mtcore.h says:
    L = C M C^T, W = W[parent] L; an end at its parent's end plus W (segment + direction l + C t),
    W its parent's where parent_frame is set."""
    values = np.asarray(values, dtype=float)
    frames, n = len(values), tree.joints
    positions, world, local = np.zeros((frames, n, 3)), np.zeros((frames, n, 3, 3)), np.zeros((frames, n, 3, 3))
    for j in tree.order:
        m = np.broadcast_to(np.eye(3), (frames, 3, 3))
        t, stretch = np.zeros((frames, 3)), np.zeros(frames)
        for c in range(tree.dof_start[j], tree.dof_start[j + 1]):
            kind, v = tree.dof_kind[c], values[:, tree.dof_column[c]]
            if kind <= RZ:
                m = axis_matrices("xyz"[kind], v * tree.angle_scale) @ m
            elif kind <= TZ:
                t[:, kind - TX] += v
            else:
                stretch += v
        c9 = tree.axis[j]
        local[:, j] = c9 @ m @ c9.T
        parent = tree.parent[j]
        if parent < 0:
            world[:, j] = local[:, j]
            positions[:, j] = tree.segment[j] + t
            continue
        world[:, j] = world[:, parent] @ local[:, j]
        vector = tree.segment[j] + tree.direction[j] * stretch[:, None] + t @ c9.T
        turn = world[:, parent] if tree.parent_frame[j] else world[:, j]
        positions[:, j] = positions[:, parent] + np.einsum("fij,fj->fi", turn, vector)
    return positions, world, local


def local_quaternions(values, tree, joints, turn) -> np.ndarray:
    """The local rotations of forward_kinematics for the chosen joints, the first turned on the left
    by turn where given, as quaternions with w >= 0 at the first frame and each next one on the
    side of the one before; (x, y, z, w) in float32, (joints, frames, 4)."""
    local = forward_kinematics(values, tree)[2][:, list(joints)]
    if turn is not None and len(joints):
        local[:, 0] = np.asarray(turn) @ local[:, 0]
    q = unroll_quaternions(matrices_to_quaternions(local), axis=0) if len(local) else np.zeros((0, len(joints), 4))
    return np.ascontiguousarray(q[..., [1, 2, 3, 0]].transpose(1, 0, 2), dtype=np.float32)


def motion_kinematics(motion):
    """(positions (frames, joints, 3) of each joint's end, local (frames, joints, 3, 3), world likewise)
    of an ASF/AMC motion, from its skeleton: a bone's local rotation is C M C^T, C from its axis
    angles in their order letters, M from its dofs in the order the ASF lists them (each new
    rotation from the left: fixed axes); a bone's end is its start plus its world rotation times
    its unit direction times its length."""
    sk = motion.skeleton
    scale = np.pi / 180 if sk.angle_unit == "deg" else 1.0
    frames = motion.frames
    names = sk.joint_names
    positions = np.zeros((frames, len(names), 3))
    local = np.zeros((frames, len(names), 3, 3))
    world = np.zeros_like(local)

    def rotation(joint, axis_order, axis_angles):
        c = matrices(np.radians(axis_angles) if scale != 1.0 else np.asarray(axis_angles, float), axis_order.lower())
        dofs = [d for d in sk.dofs(joint) if d.startswith("r")]
        m = np.broadcast_to(np.eye(3), (frames, 3, 3))
        for d in dofs:
            m = axis_matrices(d[1], motion.channel(joint, d) * scale) @ m
        return c @ m @ c.T

    root = sk.root
    local[:, 0] = rotation("root", root.axis, root.orientation)
    world[:, 0] = local[:, 0]
    t = np.stack([motion.channel("root", d) if d in root.order else np.zeros(frames) for d in ("tx", "ty", "tz")], -1)
    positions[:, 0] = np.asarray(root.position) + t
    index = {n: i for i, n in enumerate(names)}
    done = {"root"}
    pending = list(sk.bone_names)
    while pending:  # parents before children, whatever the bone order
        for name in list(pending):
            parent = sk.parent(name)
            if parent not in done:
                continue
            i, p = index[name], index[parent]
            bone = sk.bone(name)
            local[:, i] = rotation(name, bone.axis_order, bone.axis)
            world[:, i] = world[:, p] @ local[:, i]
            direction = np.asarray(bone.direction, float)
            norm = np.linalg.norm(direction)
            vector = direction / norm * bone.length if norm > 0 else np.zeros(3)
            positions[:, i] = positions[:, p] + world[:, i] @ vector
            done.add(name)
            pending.remove(name)
    return positions, local, world
