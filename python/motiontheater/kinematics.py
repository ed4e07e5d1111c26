"""Forward kinematics of skeletons and motions: joint positions and rotations.

ASF/AMC semantics (those of the HDM05 toolbox, which the tests reproduce to
1e-13): a joint's local rotation is C M C^T, C from its ``axis`` angles
about x, y and z applied in the order of its letters, M from its rotation dofs applied in the
order the ASF lists them, both about fixed axes; world rotations chain from
the root; a bone ends at its parent's end plus its world rotation times its
unit direction times its length.  The root is at ``:root position`` plus its
translation channels.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from mtcore.kinematics import DOFS, JointTree, axis_rotations

from .skeleton import Skeleton


def _frame(order: str, angles, scale: float) -> np.ndarray:
    """C of an ASF ``axis``: the angles are about x, y and z, applied in ``order`` (e.g. "ZYX")."""
    return axis_rotations(order, [angles["XYZ".index(letter)] for letter in order.upper()], scale)


@functools.lru_cache(maxsize=64)
def joint_tree(skeleton: Skeleton) -> JointTree:
    """The C kernel's tables for a skeleton: joints in ``skeleton.joint_names`` order."""
    names = skeleton.joint_names
    index = {name: i for i, name in enumerate(names)}
    scale = math.pi / 180 if skeleton.angle_unit == "deg" else 1.0
    parent = [-1] + [index[skeleton.parent(b)] for b in skeleton.bone_names]
    order, queue = [], ["root"]
    while queue:  # breadth first from the root: parents before children, whatever the bone order
        name = queue.pop(0)
        order.append(index[name])
        queue.extend(skeleton.children(name))
    root = skeleton.root
    bvh = skeleton.convention == "bvh"
    axis = [_frame(root.axis, root.orientation, scale)]
    direction, segment = [np.zeros(3)], [_replaced(root.position, root.order) if bvh else np.asarray(root.position)]
    for bone in skeleton.bones:
        d = np.asarray(bone.direction, float)
        if bvh:  # the OFFSET itself, turned by the parent; position channels replace its components
            axis.append(np.eye(3))
            direction.append(np.zeros(3))
            segment.append(_replaced(d, bone.dofs))
            continue
        axis.append(_frame(bone.axis_order, bone.axis, scale))
        norm = np.linalg.norm(d)
        unit = d / norm if norm > 0 else np.zeros(3)
        direction.append(unit)
        segment.append(unit * bone.length)
    dof_start, dof_kind, dof_column = [0], [], []
    column = 0
    for name in names:
        dofs = skeleton.dofs(name)
        entries = [(DOFS[dof], column + i) for i, dof in enumerate(dofs)]
        if bvh:  # BVH lists rotations as R = R1 R2 R3 (v' = R v): about fixed axes, the last applies first
            rotations = [e for e in entries if e[0] <= DOFS["rz"]][::-1]
            entries = [e for e in entries if e[0] > DOFS["rz"]] + rotations
        for kind, col in entries:
            dof_kind.append(kind)
            dof_column.append(col)
        column += len(dofs)
        dof_start.append(len(dof_kind))
    return JointTree(
        parent=parent,
        order=order,
        axis=axis,
        direction=direction,
        segment=segment,
        dof_start=dof_start,
        dof_kind=dof_kind,
        dof_column=dof_column,
        angle_scale=scale,
        parent_frame=[0] + [1 if bvh else 0] * len(skeleton.bones),
    )


def _replaced(offset, dofs) -> np.ndarray:
    """A BVH offset with the components that position channels replace set to zero."""
    out = np.asarray(offset, float).copy()
    for i, dof in enumerate(("tx", "ty", "tz")):
        if dof in dofs:
            out[i] = 0.0
    return out
