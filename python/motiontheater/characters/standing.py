"""A BVH rig whose rest pose does not stand, given a standing frame's pose as its rest pose.

Many rigs write their OFFSETs in each bone's own axes (LAFAN1's, Rokoko's, some Maya exports):
with every rotation zero they draw a figure lying along x, whose hip height means nothing, and
whose rest bones no other rig shares.  Retargeting plans such a rig on its *re-rested* twin: the
same joints and channels, each OFFSET turned into where it points in a standing frame, so that
the twin's rest pose is that frame's pose.  With G_j the world rotation of joint j in that frame,
twin offsets are o'_j = G_p o_j (p the parent), and a pose L_j (local rotations) of the rig is the
pose L'_j = G_p L_j G_j^T of the twin, so that both draw the same points; :class:`Rested` converts
channels both ways.  It needs three rotation channels on every joint that turns (a conjugated
rotation has no fewer), as such rigs have.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from mtcore.rotations import euler_to_matrices, matrices_to_euler

from ..model.motion import Motion
from ..model.skeleton import ROTATIONS, Skeleton


@dataclass(frozen=True, eq=False)
class Rested:
    """``skeleton``, the re-rested twin of ``original``; ``world`` (joints, 3, 3) the standing
    frame's world rotation of each joint (``joint_names`` order)."""

    original: Skeleton
    skeleton: Skeleton
    world: np.ndarray

    def into(self, values: np.ndarray) -> np.ndarray:
        """Channels of the original rig (frames, channels) as the twin's."""
        return self._convert(values, forward=True)

    def back(self, values: np.ndarray) -> np.ndarray:
        """Channels of the twin (frames, channels) as the original rig's."""
        return self._convert(values, forward=False)

    def _convert(self, values: np.ndarray, *, forward: bool) -> np.ndarray:
        skeleton, out = self.original, np.array(values, dtype=float)
        index = {n: i for i, n in enumerate(skeleton.joint_names)}
        degrees = skeleton.angle_unit == "deg"
        for name in skeleton.joint_names:
            dofs = skeleton.dofs(name)
            turning = [skeleton.first_column(name) + i for i, d in enumerate(dofs) if d in ROTATIONS]
            if not turning:
                continue
            order = "".join(d[1] for d in dofs if d in ROTATIONS)
            own = self.world[index[name]]
            parent = np.eye(3) if name == "root" else self.world[index[skeleton.parent(name)]]
            local = euler_to_matrices(out[:, turning], order, extrinsic=False, degrees=degrees)
            turned = parent @ local @ own.T if forward else parent.T @ local @ own
            out[:, turning] = matrices_to_euler(turned, order, extrinsic=False, degrees=degrees)
        return out


def rested(skeleton: Skeleton, frame: np.ndarray) -> Rested | None:
    """The twin of a BVH ``skeleton`` whose rest pose is the pose of ``frame`` (channels); None
    where a joint turns with fewer than three rotation channels (see the module docstring)."""
    for name in skeleton.joint_names:
        if 0 < sum(d in ROTATIONS for d in skeleton.dofs(name)) < 3:
            return None
    world = Motion(skeleton, np.asarray(frame, dtype=float).reshape(1, -1)).rotations()[0]
    index = {n: i for i, n in enumerate(skeleton.joint_names)}
    bones = []
    for bone in skeleton.bones:
        turned = world[index[skeleton.parent(bone.name)]] @ np.asarray(bone.direction, dtype=float)
        x, y, z = (float(v) for v in turned)
        bones.append(replace(bone, direction=(x, y, z)))
    twin = replace(skeleton, bones=tuple(bones), posed=None, standing=None)
    return Rested(skeleton, twin, world)
