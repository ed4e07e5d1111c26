"""Forward kinematics of ASF/AMC motions in vectorised numpy: the twin of the C kernel.

A bone's local rotation is C M C^T: C from its axis angles applied in their
order letters, M from its dofs applied in the order the ASF lists them (each
new rotation multiplies from the left: fixed axes).  World rotations chain
from the root; a bone's end is its start plus its world rotation times its
unit direction times its length.
"""

import numpy as np


def axis_rotation(axis: str, angles: np.ndarray) -> np.ndarray:
    """(..., 3, 3) rotations by angles (radians) about x, y or z."""
    c, s = np.cos(angles), np.sin(angles)
    one, zero = np.ones_like(angles), np.zeros_like(angles)
    rows = {
        "x": [[one, zero, zero], [zero, c, -s], [zero, s, c]],
        "y": [[c, zero, s], [zero, one, zero], [-s, zero, c]],
        "z": [[c, -s, zero], [s, c, zero], [zero, zero, one]],
    }[axis]
    return np.stack([np.stack(r, axis=-1) for r in rows], axis=-2)


def euler(order: str, angles, shape=()) -> np.ndarray:
    m = np.broadcast_to(np.eye(3), (*shape, 3, 3))
    for letter, angle in zip(order.lower(), angles):
        m = axis_rotation(letter, np.asarray(angle, dtype=float)) @ m
    return m


def forward_kinematics(motion):
    """(positions (frames, joints, 3) of each joint's end, local (frames, joints, 3, 3), world likewise)."""
    sk = motion.skeleton
    scale = np.pi / 180 if sk.angle_unit == "deg" else 1.0
    frames = motion.frames
    names = sk.joint_names
    positions = np.zeros((frames, len(names), 3))
    local = np.zeros((frames, len(names), 3, 3))
    world = np.zeros_like(local)

    def rotation(joint, axis_order, axis_angles):
        c = euler(axis_order, np.radians(axis_angles) if scale != 1.0 else axis_angles)
        dofs = [d for d in sk.dofs(joint) if d.startswith("r")]
        m = np.broadcast_to(np.eye(3), (frames, 3, 3))
        for d in dofs:
            m = axis_rotation(d[1], motion.channel(joint, d) * scale) @ m
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
