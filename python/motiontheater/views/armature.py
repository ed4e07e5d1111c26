"""The armature that the animation formats (glTF, USD, FBX) write: a tree of nodes with rest and
bind transforms, and per take each node's local rotation and translation per frame, in metres,
+Y up and +Z forward, whatever the take's unit and up axis.

A node is a point of the skeleton with a frame of axes.  A BVH joint is one (its End Sites too):
it sits where forward kinematics puts the joint and turns with it.  An ASF bone turns about its
start, so its node sits at the end of its parent bone (the root at the root's position) and
turns with the bone; a bone with no children gets a node ``<bone>_end`` at its end.  Each node's
world transform is thus exactly the project's forward kinematics: its origin the position of
the joint :attr:`Armature.origins` names, its axes that joint's world rotation, both turned by
:attr:`Armature.turn` and scaled to metres.

The numeric work is the C core's: one kernel gives the turning nodes' local rotations as
quaternions straight from the channels, each node's keys on one hemisphere (so that interpolation
between frames takes the short way); forward kinematics, a chunk of frames at a time, gives the
translations of the nodes that move.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from mtcore.kinematics import forward_kinematics, local_quaternions
from mtcore.rotations import matrices_to_quaternions

from ..feet.upright import take_forward, take_up
from ..model.motion import Motion
from ..model.skeleton import ROTATIONS, Skeleton

CHUNK = 2048  # frames per pass: the kinematics' scratch stays in cache-friendly, bounded memory
MOVES = frozenset(("tx", "ty", "tz", "l"))  # channels that move a point relative to its parent


@dataclass(frozen=True, eq=False)
class Armature:
    """The nodes of a skeleton as the animation formats write them (see the module docstring).

    ``names`` are unique; ``parents`` (nodes,) the index of each node's parent, -1 for the root
    (node 0), parents before children; ``translations`` (nodes, 3) and ``rotations`` (nodes, 4,
    quaternions x, y, z, w) the rest pose's local transforms, which the bind pose is too;
    ``rest_world`` (nodes, 4, 4) their products down the tree (column vectors, translation in the
    last column) and ``inverse_bind`` their inverses.  ``turning`` are the nodes whose rotation
    a take animates, ``moving`` those whose translation it does (the root's, and where position
    or stretch channels move a joint); the others keep their rest transform.  ``origins``
    (nodes,) is the joint (an index into ``skeleton.joint_names``) whose forward-kinematics
    position is the node's origin; ``turn`` (3 x 3) takes the take's axes to +Y up, +Z forward
    and ``scale`` its lengths to metres, so that a node's world origin is
    ``scale * turn @ positions[origins]``.  ``up`` and ``forward`` say, in words, which of the
    take's axes became +Y and +Z, and why.
    """

    skeleton: Skeleton
    names: tuple[str, ...]
    parents: np.ndarray
    origins: np.ndarray
    frames_of: np.ndarray  # (nodes,) the joint whose world rotation is the node's axes
    translations: np.ndarray
    rotations: np.ndarray
    rest_world: np.ndarray
    inverse_bind: np.ndarray
    turning: np.ndarray
    moving: np.ndarray
    turn: np.ndarray
    scale: float
    up: str
    forward: str

    @property
    def nodes(self) -> int:
        """The number of nodes."""
        return len(self.names)

    def children(self, node: int) -> np.ndarray:
        """The nodes whose parent is ``node``."""
        return np.flatnonzero(self.parents == node)


@dataclass(frozen=True, eq=False)
class Track:
    """One take's animation of an :class:`Armature`: ``rotations`` (turning nodes, frames, 4)
    float32 quaternions x, y, z, w, each node's keys on one hemisphere; ``translations``
    (moving nodes, frames, 3) float32 metres; ``frame_rate`` Hz; frames numbered from
    ``first_frame``; ``name`` the take's (its file's stem)."""

    name: str
    rotations: np.ndarray
    translations: np.ndarray
    frame_rate: float
    first_frame: int

    @property
    def frames(self) -> int:
        """The number of frames."""
        return self.rotations.shape[1] if self.rotations.size else self.translations.shape[1]


def animated(motions: Motion | Sequence[Motion], names: Sequence[str] | None = None) -> tuple[Armature, list[Track]]:
    """The armature of takes of one skeleton and each take's track (``names``: the tracks',
    default :func:`take_names`).  The first take decides the up and forward axes.  ValueError
    when the takes have different skeletons, a take holds NaN or inf, the skeleton has no bone,
    or a joint's name is not text (the formats store names as UTF-8)."""
    takes = [motions] if isinstance(motions, Motion) else list(motions)
    if not takes:
        raise ValueError("no take to export")
    names = list(names) if names is not None else take_names(takes)
    first = takes[0]
    for name, take in zip(names, takes):
        if not np.isfinite(take.values).all():
            raise ValueError(f"{name}: the take holds NaN or inf values; fill the gaps first (the fill_gaps step)")
        if take is not first and not same_rig(take.skeleton, first.skeleton):
            raise ValueError(
                f"{name} has another skeleton than {names[0]}: takes in one file share one skeleton; "
                "export them to separate files"
            )
    armature = rest_armature(first)
    for name in armature.names:
        try:
            name.encode("utf-8")
        except UnicodeEncodeError:
            raise ValueError(f"joint name {name!r} is not UTF-8 text, which the animation formats store") from None
    return armature, [track(armature, take, name) for take, name in zip(takes, names)]


def take_names(motions: Sequence[Motion]) -> list[str]:
    """Each take's name for its animation: its file's stem where it was read from one, else
    take, take_2, ...; unique."""
    names: list[str] = []
    for i, motion in enumerate(motions):
        origin = motion.origin.file.path if motion.origin is not None else None
        base = os.path.splitext(os.path.basename(origin))[0] if origin else ("take" if i == 0 else f"take_{i + 1}")
        name, n = base, 2
        while name in names:
            name, n = f"{base}_{n}", n + 1
        names.append(name)
    return names


def same_rig(a: Skeleton, b: Skeleton) -> bool:
    """Whether two skeletons have the same joints, channels and rest pose (to rounding)."""
    if a.joint_names != b.joint_names or a.channels != b.channels or a.convention != b.convention:
        return False
    scale = a.meters_per_unit / b.meters_per_unit
    return bool(np.allclose(a.rest_positions(), b.rest_positions() / scale, rtol=1e-9, atol=1e-9 * _size(a)))


def _size(skeleton: Skeleton) -> float:
    extent = np.ptp(skeleton.rest_positions(), axis=0).max(initial=0.0)
    return float(extent) if extent > 0 else 1.0


def _layout(skeleton: Skeleton) -> tuple[list[str], list[int], list[int], list[int], list[bool]]:
    """Per node, parents first: name, parent node, origin joint, frame joint, and whether it is
    a joint's own node (not an ASF bone's end)."""
    tree = skeleton.tree
    order = [int(j) for j in tree.order]  # parents first, whatever the file's bone order
    node_of = {j: n for n, j in enumerate(order)}
    points = skeleton.point_names
    names = [points[j] for j in order]
    parents = [node_of[int(tree.parent[j])] if tree.parent[j] >= 0 else -1 for j in order]
    if skeleton.convention == "bvh":
        return names, parents, order, order, [True] * len(names)
    origins = [max(int(tree.parent[j]), 0) for j in order]
    frames, own = list(order), [True] * len(names)
    taken = set(names)
    for j in order[1:]:
        if not skeleton.children(skeleton.joint_names[j]):
            names.append(_unique(f"{points[j]}_end", taken))
            parents.append(node_of[j])
            origins.append(j)
            frames.append(j)
            own.append(False)
    return names, parents, origins, frames, own


def _unique(name: str, taken: set[str]) -> str:
    found, n = name, 2
    while found in taken:
        found, n = f"{name}{n}", n + 1
    taken.add(found)
    return found


def rest_values(skeleton: Skeleton) -> np.ndarray:
    """(1, channels): the calibration pose's channels: zero, but a BVH's position channels,
    which hold their joint's OFFSET there (as :meth:`Skeleton.rest_positions` draws it)."""
    values = np.zeros((1, len(skeleton.channels)))
    if skeleton.convention == "bvh":
        for column, (joint, dof) in enumerate(skeleton.channels):
            if dof in ("tx", "ty", "tz"):
                offset = skeleton.root.position if skeleton.is_root(joint) else skeleton.bone(joint).direction
                values[0, column] = offset["xyz".index(dof[1])]
    return values


def _turn(motion: Motion) -> tuple[np.ndarray, str, str]:
    """The turn that stands the take along +Y and faces it along +Z (a signed permutation, exact),
    and what it took as up and forward, in words."""
    up = take_up(motion)
    turn = up.turn
    facing = take_forward(motion, up)
    if facing.axis is None:
        return turn, f"{up.axis} is up ({up.reason})", f"forward is unknown ({facing.reason}): kept"
    sign = -1.0 if facing.axis.startswith("-") else 1.0
    ahead = turn @ (sign * np.eye(3)["xyz".index(facing.axis[-1])])
    # a quarter turn about +Y at a time, until the facing lies along +Z
    quarter = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])
    for _ in range(4):
        if ahead[2] > 0.5:
            break
        ahead, turn = quarter @ ahead, quarter @ turn
    return turn, f"{up.axis} is up ({up.reason})", f"{facing.axis} is forward ({facing.reason})"


def rest_armature(motion: Motion) -> Armature:
    """The armature of a take's skeleton, turned as the take stands (see :class:`Armature`)."""
    skeleton = motion.skeleton
    if len(skeleton.joint_names) < 2:
        raise ValueError("the skeleton has a root and no bone: there is nothing to animate")
    names, parents, origins, frames_of, own = _layout(skeleton)
    turn, up, forward = _turn(motion)
    scale = skeleton.meters_per_unit
    parent = np.array(parents)
    origin, frame = np.array(origins), np.array(frames_of)
    rotations, translations = _locals(skeleton, rest_values(skeleton), parent, origin, frame, own, turn, scale)
    local = np.zeros((len(names), 4, 4))
    local[:, :3, :3] = rotations[0]
    local[:, :3, 3] = translations[0]
    local[:, 3, 3] = 1.0
    world = local.copy()
    for n in range(1, len(names)):
        world[n] = world[parent[n]] @ local[n]
    dofs = [skeleton.dofs(skeleton.joint_names[j]) for j in frame]
    turning = [n for n in range(len(names)) if own[n] and set(dofs[n]) & set(ROTATIONS)]
    moving = [
        n for n in range(len(names)) if (n == 0 or origin[n] != origin[parent[n]]) and _moves(skeleton, origin[n])
    ]
    return Armature(
        skeleton=skeleton,
        names=tuple(names),
        parents=parent,
        origins=origin,
        frames_of=frame,
        translations=translations[0],
        rotations=matrices_to_quaternions(rotations[0])[:, [1, 2, 3, 0]],
        rest_world=world,
        inverse_bind=np.linalg.inv(world),
        turning=np.array(turning, dtype=np.intp),
        moving=np.array(moving, dtype=np.intp),
        turn=turn,
        scale=scale,
        up=up,
        forward=forward,
    )


def _moves(skeleton: Skeleton, joint: int) -> bool:
    return bool(MOVES & set(skeleton.dofs(skeleton.joint_names[joint])))


def _locals(skeleton, values, parent, origin, frame, own, turn, scale) -> tuple[np.ndarray, np.ndarray]:
    """(frames, nodes, 3, 3) local rotations and (frames, nodes, 3) local translations (metres)
    of every node for a few frames of channels (the rest pose's, or a test's)."""
    positions, world, local = forward_kinematics(values, skeleton.tree, world=True, local=True)
    assert world is not None and local is not None  # asked for
    count = len(parent)
    rotations = np.tile(np.eye(3), (len(values), count, 1, 1))
    joint_nodes = [n for n in range(count) if own[n]]
    rotations[:, joint_nodes] = local[:, frame[joint_nodes]]
    rotations[:, 0] = turn @ rotations[:, 0]
    translations = np.empty((len(values), count, 3))
    translations[:, 0] = scale * positions[:, origin[0]] @ turn.T
    rest = np.arange(1, count)
    step = positions[:, origin[rest]] - positions[:, origin[parent[rest]]]
    axes = world[:, frame[parent[rest]]]
    translations[:, 1:] = scale * np.einsum("fnij,fni->fnj", axes, step)
    return rotations, translations


def track(armature: Armature, motion: Motion, name: str = "take") -> Track:
    """A take's track on an armature of its skeleton (see :func:`animated`)."""
    tree = motion.skeleton.tree
    frames = motion.frames
    turning, moving = armature.turning, armature.moving
    root_turns = bool(len(turning)) and turning[0] == 0
    rotations = local_quaternions(
        motion.values, tree, armature.frames_of[turning], armature.turn if root_turns else None
    )
    translations = np.empty((len(moving), frames, 3), np.float32)
    shifted = moving[moving > 0]
    root_moves = bool(len(moving)) and moving[0] == 0
    origin, parent, frame = armature.origins, armature.parents, armature.frames_of
    # forward kinematics of the joints the translations need only: often the root alone
    needed, index = tree.pruned(np.concatenate([origin[moving], origin[parent[shifted]], frame[parent[shifted]]]))
    for start in range(0, frames if len(moving) else 0, CHUNK):
        values = motion.values[start : start + CHUNK]
        positions, world, _ = forward_kinematics(values, needed, world=bool(len(shifted)), workers=1)
        if root_moves:
            translations[0, start : start + len(values)] = (
                armature.scale * positions[:, index[origin[0]]] @ armature.turn.T
            )
        if len(shifted):
            assert world is not None  # asked for
            step = positions[:, index[origin[shifted]]] - positions[:, index[origin[parent[shifted]]]]
            axes = world[:, index[frame[parent[shifted]]]]
            moved = armature.scale * np.einsum("fnij,fni->nfj", axes, step)
            translations[int(root_moves) :, start : start + len(values)] = moved
    return Track(name, rotations, translations, motion.frame_rate, motion.first_frame)
