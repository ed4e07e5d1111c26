"""Forward kinematics of joint trees over frames, in C (see ``mt_forward_kinematics``).

Array level: joints are indices; motiontheater builds the tables from a skeleton.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._cdata import c_array
from ._mtcore import lib
from ._parallel import even_bounds, run_ranges, thread_count

__all__ = ["DOFS", "JointTree", "forward_kinematics"]

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


def _doubles(a) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=np.float64)


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
        n = len(self.parent)
        fields = dict(
            parent=(np.int64, (n,)),
            order=(np.int64, (n,)),
            axis=(np.float64, (n, 3, 3)),
            direction=(np.float64, (n, 3)),
            segment=(np.float64, (n, 3)),
            dof_start=(np.uintp, (n + 1,)),
            dof_kind=(np.intc, None),
            dof_column=(np.uintp, None),
            parent_frame=(np.uint8, (n,)),
        )
        if self.parent_frame is None:
            object.__setattr__(self, "parent_frame", np.zeros(n, np.uint8))
        for name, (dtype, shape) in fields.items():
            array = np.ascontiguousarray(getattr(self, name), dtype=dtype)
            if shape is not None and array.shape != shape:
                raise ValueError(f"{name} must have shape {shape}, got {array.shape}")
            array.flags.writeable = False
            object.__setattr__(self, name, array)
        if len(self.dof_kind) != len(self.dof_column) or (n and self.dof_start[-1] != len(self.dof_kind)):
            raise ValueError("dof_start must end at the length of dof_kind and dof_column")

    @property
    def joints(self) -> int:
        """The number of joints."""
        return len(self.parent)


def forward_kinematics(
    values: np.ndarray, tree: JointTree, *, world: bool = False, local: bool = False, workers: int | None = None
) -> tuple[np.ndarray, np.ndarray | None, np.ndarray | None]:
    """Positions (frames, joints, 3) of each joint's end, and optionally world and
    local rotations (frames, joints, 3, 3), for values (frames, channels).
    Frames are split over the cores for large motions (``workers`` as for the filters)."""
    values = _doubles(values)
    if values.ndim != 2:
        raise ValueError(f"values must be (frames, channels), got shape {values.shape}")
    frames, channels = values.shape
    if len(tree.dof_column) and tree.dof_column.max() >= channels:
        raise ValueError(f"the tree reads column {tree.dof_column.max()} but values have {channels} channels")
    n = tree.joints
    positions = np.empty((frames, n, 3))
    world_out = np.empty((frames, n, 3, 3)) if world else None
    local_out = np.empty((frames, n, 3, 3)) if local else None
    bounds = even_bounds(frames, thread_count(workers, frames * n >= _PARALLEL_MIN_TRANSFORMS))
    args = (
        c_array(values),
        frames,
        channels,
        n,
        c_array(tree.parent, "long long[]"),
        c_array(tree.order, "long long[]"),
        c_array(tree.axis),
        c_array(tree.direction),
        c_array(tree.segment),
        c_array(tree.dof_start, "size_t[]"),
        c_array(tree.dof_kind, "int[]"),
        c_array(tree.dof_column, "size_t[]"),
        c_array(tree.parent_frame, "unsigned char[]"),
        tree.angle_scale,
    )
    outs = (c_array(positions), c_array(world_out), c_array(local_out))

    run_ranges(lambda begin, end: lib.mt_forward_kinematics(*args, begin, end, *outs), bounds, "mt_forward_kinematics")
    return positions, world_out, local_out
