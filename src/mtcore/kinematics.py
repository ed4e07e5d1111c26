"""Forward kinematics of joint trees over frames, in C (see ``mt_forward_kinematics``).

Array level: joints are indices; motiontheater builds the tables from a skeleton.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from . import _checks
from ._cdata import c_array
from ._mtcore import lib
from ._parallel import even_bounds, run_ranges, thread_count
from ._status import check

if TYPE_CHECKING:
    from _cffi_backend import _CDataBase as CData

__all__ = ["DOFS", "JointTree", "Kinematics", "forward_kinematics", "local_quaternions", "world_kinematics"]

DOFS = {
    "rx": lib.MT_DOF_RX,
    "ry": lib.MT_DOF_RY,
    "rz": lib.MT_DOF_RZ,
    "tx": lib.MT_DOF_TX,
    "ty": lib.MT_DOF_TY,
    "tz": lib.MT_DOF_TZ,
    "l": lib.MT_DOF_L,
}
_PARALLEL_MIN_TRANSFORMS = 20_000  # frames x joints below which one thread is faster


@dataclass(frozen=True, eq=False)
class JointTree:
    """The rest data of a joint tree, as the C kernel takes it (see mtcore.h).

    ``parent`` (joints,) int, -1 for a root; ``order`` visits parents first;
    ``axis`` (joints, 3, 3); ``direction`` and ``segment`` (joints, 3);
    ``dof_start`` (joints + 1,) into ``dof_kind`` / ``dof_column``;
    ``parent_frame`` (joints,) marks joints whose segment turns with their
    parent (BVH) rather than with themselves (ASF, the default).
    """

    parent: np.ndarray
    order: np.ndarray
    axis: np.ndarray
    direction: np.ndarray
    segment: np.ndarray
    dof_start: np.ndarray
    dof_kind: np.ndarray
    dof_column: np.ndarray
    angle_scale: float = 1.0
    parent_frame: np.ndarray | None = None

    def __post_init__(self) -> None:
        parent = _checks.integers(self.parent, "parent", (None,), -1, len(np.asarray(self.parent)))
        n = len(parent)
        dof_kind = _checks.integers(self.dof_kind, "dof_kind", (None,), min(DOFS.values()), max(DOFS.values()) + 1)
        fields = dict(
            parent=parent,
            order=_checks.integers(self.order, "order", (n,), 0, n),
            axis=_checks.real(self.axis, "axis", (n, 3, 3)),
            direction=_checks.real(self.direction, "direction", (n, 3)),
            segment=_checks.real(self.segment, "segment", (n, 3)),
            dof_start=_checks.integers(self.dof_start, "dof_start", (n + 1,), 0, len(dof_kind) + 1, np.uintp),
            dof_kind=dof_kind.astype(np.intc),
            dof_column=_checks.integers(self.dof_column, "dof_column", (len(dof_kind),), 0, 2**62, np.uintp),
            parent_frame=np.zeros(n, np.uint8)
            if self.parent_frame is None
            else _checks.integers(self.parent_frame, "parent_frame", (n,), 0, 2, np.uint8),
        )
        for name, array in fields.items():
            array.flags.writeable = False
            object.__setattr__(self, name, array)
        scale = _checks.real(self.angle_scale, "angle_scale", ())
        if not np.isfinite(scale):
            raise ValueError(f"angle_scale must be finite, got {float(scale)}")
        object.__setattr__(self, "angle_scale", float(scale))
        starts = self.dof_start
        if n and (starts[0] != 0 or starts[-1] != len(dof_kind) or (np.diff(starts.astype(np.int64)) < 0).any()):
            raise ValueError(
                f"dof_start must rise from 0 to the length of dof_kind ({len(dof_kind)}), got {starts.tolist()}"
            )
        seen = np.zeros(n, bool)
        for i, j in enumerate(self.order.tolist()):
            if seen[j]:
                raise ValueError(f"order must list every joint once, got joint {j} twice (order[{i}])")
            p = int(self.parent[j])
            if p >= 0 and not seen[p]:
                raise ValueError(f"order must list each joint after its parent: joint {j} at order[{i}] before {p}")
            seen[j] = True

    @property
    def joints(self) -> int:
        """The number of joints."""
        return len(self.parent)

    @cached_property
    def kernel_tables(self) -> tuple[CData, CData, CData, CData, CData, CData, CData, CData, CData]:
        """The tables as ``mt_forward_kinematics`` takes them, made once (a tree serves every
        take of its skeleton): parent, order, axis, direction, segment, dof_start, dof_kind,
        dof_column, parent_frame."""
        return (
            c_array(self.parent, "long long[]"),
            c_array(self.order, "long long[]"),
            c_array(self.axis),
            c_array(self.direction),
            c_array(self.segment),
            c_array(self.dof_start, "size_t[]"),
            c_array(self.dof_kind, "int[]"),
            c_array(self.dof_column, "size_t[]"),
            c_array(self.parent_frame, "unsigned char[]"),
        )

    @cached_property
    def channels_read(self) -> int:
        """How many channels a frame must have for the tree to read it (its last column + 1)."""
        return int(self.dof_column.max()) + 1 if len(self.dof_column) else 0

    def pruned(self, joints) -> tuple[JointTree, np.ndarray]:
        """The tree of ``joints`` (indices) and their ancestors only, and for each joint of this
        tree its index in that one (-1 where left out).  Forward kinematics of the pruned tree,
        on the same values, puts the joints it keeps where this tree's does, at their cost only."""
        wanted = _checks.integers(joints, "joints", (None,), 0, self.joints)
        keep = np.zeros(self.joints, bool)
        for j in wanted.tolist():
            while j >= 0 and not keep[j]:
                keep[j] = True
                j = int(self.parent[j])
        kept = np.flatnonzero(keep)
        index = np.full(self.joints, -1, np.intp)
        index[kept] = np.arange(len(kept))
        parent = self.parent[kept]
        slices = [np.arange(self.dof_start[j], self.dof_start[j + 1], dtype=np.intp) for j in kept]
        dofs = np.concatenate(slices) if slices else np.zeros(0, np.intp)
        tree = JointTree(
            parent=np.where(parent >= 0, index[np.maximum(parent, 0)], -1),
            order=index[self.order[keep[self.order]]],
            axis=self.axis[kept],
            direction=self.direction[kept],
            segment=self.segment[kept],
            dof_start=np.concatenate([[0], np.cumsum([len(d) for d in slices], dtype=np.intp)]),
            dof_kind=self.dof_kind[dofs],
            dof_column=self.dof_column[dofs],
            angle_scale=self.angle_scale,
            parent_frame=None if self.parent_frame is None else self.parent_frame[kept],
        )
        return tree, index


def _values_of(values: np.ndarray, tree: JointTree) -> np.ndarray:
    """The channels (frames, channels) checked against the tree that reads them."""
    if not isinstance(tree, JointTree):
        raise TypeError(f"tree must be a JointTree, got {type(tree).__name__}")
    values = _checks.real(values, "values", (None, None))
    if tree.channels_read > values.shape[1]:
        raise ValueError(f"the tree reads column {tree.channels_read - 1} but values have {values.shape[1]} channels")
    return values


class Kinematics(NamedTuple):
    """Every joint's position (frames, joints, 3) and the world rotations (frames, len(turned), 3,
    3) of the joints ``turned`` lists (ascending; every joint unless fewer were asked for), as
    :func:`world_kinematics` gives them: what a caller that needs both for several purposes works
    out once and hands on."""

    positions: np.ndarray
    world: np.ndarray
    turned: np.ndarray

    def rows(self, joints: ArrayLike) -> np.ndarray:
        """Each joint's row of ``world``; ValueError for a joint whose rotation was not kept."""
        # a few joints of a few kept: Python's lookups cost less than numpy's calls
        index = {joint: row for row, joint in enumerate(self.turned.tolist())}
        wanted = np.asarray(joints, dtype=np.intp)
        try:
            return np.array([index[joint] for joint in wanted.ravel().tolist()], np.intp).reshape(wanted.shape)
        except KeyError as e:
            raise ValueError(f"no world rotation of joint {e.args[0]} was kept") from None


def forward_kinematics(
    values: np.ndarray,
    tree: JointTree,
    *,
    world: bool = False,
    local: bool = False,
    turned: ArrayLike | None = None,
    workers: int | None = None,
    out: tuple[np.ndarray | None, np.ndarray | None, np.ndarray | None] | None = None,
) -> tuple[np.ndarray, np.ndarray | None, np.ndarray | None]:
    """Positions (frames, joints, 3) of each joint's end, and optionally world and
    local rotations (frames, joints, 3, 3), for values (frames, channels); ``turned`` (joint
    indices, ascending) keeps the world rotations to those joints' (frames, len(turned), 3, 3),
    for a caller that reads a few of them (they are most of the memory written).
    ``out``: C-contiguous float64 arrays of those shapes to write the positions, world and local
    rotations into (None: a new one), for a caller that works out many takes one after another
    (fresh memory costs more than the kinematics of a short take).
    Frames are split over the cores for large motions (``workers`` as for the filters)."""
    values = _values_of(values, tree)
    frames, channels = values.shape
    n = tree.joints
    kept, rows = None, None  # rows: each joint's row of the world rotations (-1: not kept)
    if turned is not None:
        kept = _checks.integers(turned, "turned", (None,), 0, n)
        if np.any(np.diff(kept) <= 0):
            raise ValueError("turned must list joints in ascending order, each once")
        rows = np.full(n, -1, np.int64)
        rows[kept] = np.arange(len(kept))
    into = (None, None, None) if out is None else out
    if len(into) != 3:
        raise ValueError(f"out must be (positions, world, local), each an array or None; got {len(into)} items")
    for given, name, asked in zip(into[1:], ("world", "local"), (world, local)):
        if given is not None and not asked:
            raise ValueError(f"out {name} is given, but its rotations are not asked for")
    positions = _made(into[0], "out positions", (frames, n, 3), values)
    world_out = _made(into[1], "out world", (frames, n if kept is None else len(kept), 3, 3), values) if world else None
    local_out = _made(into[2], "out local", (frames, n, 3, 3), values) if local else None
    bounds = even_bounds(frames, thread_count(workers, frames * n >= _PARALLEL_MIN_TRANSFORMS))
    args = (c_array(values), frames, channels, n, *tree.kernel_tables, tree.angle_scale)
    outs = (
        c_array(positions),
        c_array(world_out),
        c_array(local_out),
        c_array(rows, "long long[]"),
        0 if kept is None else len(kept),
    )

    run_ranges(lambda begin, end: lib.mt_forward_kinematics(*args, begin, end, *outs), bounds, "mt_forward_kinematics")
    return positions, world_out, local_out


def _made(given: np.ndarray | None, name: str, shape: tuple, values: np.ndarray) -> np.ndarray:
    """The output array given (checked), or a new one."""
    if given is None:
        return np.empty(shape)
    if np.may_share_memory(given, values):
        raise ValueError(f"{name} shares memory with the values it would be worked out from")
    return _checks.output(given, name, shape)


def world_kinematics(
    values: np.ndarray,
    tree: JointTree,
    *,
    turned: ArrayLike | None = None,
    workers: int | None = None,
    out: tuple[np.ndarray, np.ndarray] | None = None,
) -> Kinematics:
    """Every joint's position and the world rotations of ``turned`` (default every joint's):
    :func:`forward_kinematics` with ``world=True``, into ``out`` (positions, world) where given."""
    into = None if out is None else (*out, None)
    positions, world, _ = forward_kinematics(values, tree, world=True, turned=turned, workers=workers, out=into)
    assert world is not None  # asked for
    kept = np.arange(tree.joints) if turned is None else np.asarray(turned, dtype=np.intp)
    return Kinematics(positions, world, kept)


def local_quaternions(values: np.ndarray, tree: JointTree, joints, turn: np.ndarray | None = None) -> np.ndarray:
    """The local rotations of ``joints`` (indices) per frame as float32 unit quaternions
    (x, y, z, w), (len(joints), frames, 4): each joint's keys together, the first with w >= 0 and
    each next on the hemisphere of the one before; ``turn`` (3, 3) turns the first joint's on
    the left.  The local rotations are :func:`forward_kinematics`'s, without the rest of its work:
    what an animation file stores, one pass over the frames."""
    values = _values_of(values, tree)
    frames, channels = values.shape
    chosen = _checks.integers(joints, "joints", (None,), 0, tree.joints)
    turned = None if turn is None else _checks.real(turn, "turn", (3, 3))
    out = np.empty((len(chosen), frames, 4), np.float32)
    check(
        lib.mt_local_quaternions(
            c_array(values),
            frames,
            channels,
            tree.joints,
            c_array(tree.axis),
            c_array(tree.dof_start, "size_t[]"),
            c_array(tree.dof_kind, "int[]"),
            c_array(tree.dof_column, "size_t[]"),
            tree.angle_scale,
            len(chosen),
            c_array(chosen, "long long[]"),
            c_array(turned),
            c_array(out, "float[]"),
        ),
        "mt_local_quaternions",
    )
    return out
