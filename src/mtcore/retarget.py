"""Retargeting in C (see ``mt_retarget``): a source motion as the rotation channels of a target tree.

Array level: joints are indices and trees are :class:`~mtcore.kinematics.JointTree`
tables; motiontheater works out the plan from two skeletons and a joint map.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ._cdata import c_array
from ._mtcore import ffi, lib
from ._parallel import even_bounds, run_ranges, thread_count
from .kinematics import JointTree

__all__ = ["RetargetPlan", "retarget_rotations"]

_PARALLEL_MIN_TRANSFORMS = 20_000  # frames x joints below which one thread is faster


@dataclass(frozen=True, eq=False)
class RetargetPlan:
    """Per target joint (rows), what ``mt_retarget`` does (see mtcore.h):

    ``follow`` (targets,) the source joint followed, -1 for rest;
    ``correction`` (targets, 3, 3) P, the wanted world rotation being
    ``align @ W_source @ P``; ``key_points`` (targets, 2) source points
    a, b whose direction p_b - p_a the joint's bone, ``key_vector``
    (targets, 3) at rest, should point in (-1 -1: none); ``refit``
    (targets,) bool: turn it there each frame; ``hinge`` (targets,) a
    one-channel joint below whose plane the joint turns to contain its
    source direction (-1: none); ``aim`` (targets, 3) the rest direction
    that one or two rotation channels aim (zero: none); ``align`` (3, 3)
    source world axes to target world axes.
    """

    follow: np.ndarray
    correction: np.ndarray
    key_points: np.ndarray
    key_vector: np.ndarray
    refit: np.ndarray
    hinge: np.ndarray
    aim: np.ndarray
    align: np.ndarray

    def __post_init__(self) -> None:
        n = len(self.follow)
        fields = dict(
            follow=(np.int64, (n,)),
            correction=(np.float64, (n, 3, 3)),
            key_points=(np.int64, (n, 2)),
            key_vector=(np.float64, (n, 3)),
            refit=(np.uint8, (n,)),
            hinge=(np.int64, (n,)),
            aim=(np.float64, (n, 3)),
            align=(np.float64, (3, 3)),
        )
        for name, (dtype, shape) in fields.items():
            array = np.ascontiguousarray(getattr(self, name), dtype=dtype)
            if array.shape != shape:
                raise ValueError(f"{name} must have shape {shape}, got {array.shape}")
            array.flags.writeable = False
            object.__setattr__(self, name, array)


def _tree(tree: JointTree, channels: int, keep: list) -> Any:
    """The ``struct mt_tree`` of a JointTree; ``keep`` holds the buffers while C reads them."""
    arrays = dict(
        parent=c_array(tree.parent, "long long[]"),
        order=c_array(tree.order, "long long[]"),
        axis=c_array(tree.axis),
        direction=c_array(tree.direction),
        segment=c_array(tree.segment),
        dof_start=c_array(tree.dof_start, "size_t[]"),
        dof_column=c_array(tree.dof_column, "size_t[]"),
        dof_kind=c_array(tree.dof_kind, "int[]"),
        parent_frame=c_array(tree.parent_frame, "unsigned char[]"),
    )
    keep.extend(arrays.values())
    struct: Any = ffi.new("struct mt_tree *")  # structs: fields by name
    struct.joints = tree.joints
    struct.channels = channels
    struct.angle_scale = tree.angle_scale
    for name, pointer in arrays.items():
        setattr(struct, name, pointer)
    return struct


def retarget_rotations(
    values: np.ndarray,
    source: JointTree,
    target: JointTree,
    target_channels: int,
    plan: RetargetPlan,
    *,
    out: np.ndarray | None = None,
    workers: int | None = None,
) -> np.ndarray:
    """The target's rotation channels (frames, target_channels) for source ``values`` (frames,
    source channels); the other channels of ``out`` (zeros when not given) are left as they are.
    Frames are split over the cores for large motions (``workers`` as for the filters)."""
    values = np.ascontiguousarray(values, dtype=np.float64)
    if values.ndim != 2:
        raise ValueError(f"values must be (frames, channels), got shape {values.shape}")
    frames, channels = values.shape
    if len(source.dof_column) and source.dof_column.max() >= channels:
        raise ValueError(f"the source tree reads column {source.dof_column.max()} but values have {channels} channels")
    if len(target.dof_column) and target.dof_column.max() >= target_channels:
        raise ValueError(f"the target tree reads column {target.dof_column.max()} of {target_channels} channels")
    if len(plan.follow) != target.joints:
        raise ValueError(f"the plan has {len(plan.follow)} rows for {target.joints} target joints")
    if plan.follow.max(initial=-1) >= source.joints or plan.key_points.max(initial=-1) >= source.joints:
        raise ValueError(f"the plan names a source joint beyond the source's {source.joints}")
    if plan.hinge.max(initial=-1) >= target.joints:
        raise ValueError(f"the plan names a target joint beyond the target's {target.joints}")
    if out is None:
        out = np.zeros((frames, target_channels))
    elif out.shape != (frames, target_channels) or out.dtype != np.float64 or not out.flags.c_contiguous:
        raise ValueError(f"out must be a C-contiguous float64 array of shape {(frames, target_channels)}")
    keep: list = []
    struct_plan: Any = ffi.new("struct mt_retarget_plan *")
    pointer = c_array(plan.refit, "unsigned char[]")
    keep.append(pointer)
    struct_plan.refit = pointer
    for name in ("follow", "key_points", "hinge"):
        pointer = c_array(getattr(plan, name), "long long[]")
        keep.append(pointer)
        setattr(struct_plan, name, pointer)
    for name in ("correction", "key_vector", "aim"):
        pointer = c_array(getattr(plan, name))
        keep.append(pointer)
        setattr(struct_plan, name, pointer)
    struct_plan.align = list(plan.align.ravel())
    source_struct = _tree(source, channels, keep)
    target_struct = _tree(target, target_channels, keep)
    data, result = c_array(values), c_array(out)
    bounds = even_bounds(frames, thread_count(workers, frames * target.joints >= _PARALLEL_MIN_TRANSFORMS))
    run_ranges(
        lambda begin, end: lib.mt_retarget(data, frames, source_struct, target_struct, struct_plan, begin, end, result),
        bounds,
        "mt_retarget",
    )
    return out
