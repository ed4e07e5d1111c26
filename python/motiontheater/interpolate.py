"""Interpolators and filters over frame ranges, stacked in order (the CS838 "interpolator stack").

An interpolator replaces the frames strictly between two key frames a and b
by interpolating the keys; a filter smooths the frames a..b only.  Rotation
interpolators work on joints with three rotation channels, through unit
quaternions (mtcore.rotations, in C); other channels interpolate linearly.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from mtcore import median_filter1d
from mtcore import rotations as rot

from .filtering import FILTERS, filter_motion
from .motion import Motion
from .skeleton import ROTATIONS

INTERPOLATORS = ("euler", "slerp", "expmap", "aligned_expmap")
STEPS = (*INTERPOLATORS, "median3", *FILTERS)


def _convention(motion: Motion, dofs: tuple[str, ...]) -> tuple[str, bool]:
    """(order, extrinsic) of a joint's rotation channels: ASF applies them in order about fixed
    axes (extrinsic); BVH lists R = R1 R2 R3 (intrinsic, in the listed order)."""
    return "".join(d[1] for d in dofs), motion.skeleton.convention != "bvh"


def interpolate(
    motion: Motion, first: int, last: int, kind: str = "slerp", joints: Iterable[str] | None = None
) -> Motion:
    """A new motion whose frames first+1 .. last-1 (frame numbers) interpolate the keys at
    ``first`` and ``last``: "euler" (linear on the stored angles), "slerp" (quaternions, the
    short arc), "expmap" (linear on exponential maps) or "aligned_expmap" (the start key
    flipped to the end key's hemisphere first, so that it too takes the short way)."""
    if kind not in INTERPOLATORS:
        raise ValueError(f"kind must be one of {', '.join(INTERPOLATORS)}, got {kind!r}")
    a, b = _rows(motion, first, last)
    values = motion.values.copy()
    t = (np.arange(a + 1, b) - a) / (b - a)
    skeleton = motion.skeleton
    for joint in skeleton.joint_names if joints is None else tuple(joints):
        dofs = skeleton.dofs(joint)
        columns = motion.columns(joint)
        rotations = tuple(d for d in dofs if d in ROTATIONS)
        rotation_columns = [c for c, d in zip(columns, dofs) if d in ROTATIONS]
        linear = [c for c in columns if kind == "euler" or len(rotations) != 3 or c not in rotation_columns]
        values[a + 1 : b, linear] = values[a, linear] + t[:, None] * (values[b, linear] - values[a, linear])
        if kind == "euler" or len(rotations) != 3:
            continue
        order, extrinsic = _convention(motion, rotations)
        degrees = skeleton.angle_unit == "deg"
        keys = rot.euler_to_quaternions(
            values[[a, b]][:, rotation_columns], order, extrinsic=extrinsic, degrees=degrees
        )
        if kind == "slerp":
            q = rot.slerp(keys[0], keys[1], t)
        else:
            v = rot.quaternions_to_rotvecs(keys)
            q = rot.rotvecs_to_quaternions(rot.interpolate_rotvecs(v[0], v[1], t, aligned=kind == "aligned_expmap"))
        angles = rot.quaternions_to_euler(q, order, extrinsic=extrinsic, degrees=degrees)
        # of the equivalent Euler triples, each frame's nearest the one before, from the first key on
        path = rot.unroll_euler(np.concatenate([values[a : a + 1, rotation_columns], angles]), order, degrees=degrees)
        values[a + 1 : b, rotation_columns] = path[1:]
    values.flags.writeable = False
    return motion.replace(values=values)


def median3(motion: Motion, first: int, last: int, joints: Iterable[str] | None = None) -> Motion:
    """The 3-frame median "cut" filter over frames first .. last only (edges held inside the range)."""
    a, b = _rows(motion, first, last)
    columns = [c for j in (motion.skeleton.joint_names if joints is None else tuple(joints)) for c in motion.columns(j)]
    values = motion.values.copy()
    values[a : b + 1, columns] = median_filter1d(values[a : b + 1][:, columns], 3, axis=0, mode="nearest")
    values.flags.writeable = False
    return motion.replace(values=values)


def _rows(motion: Motion, first: int, last: int) -> tuple[int, int]:
    f0, f1 = motion.first_frame, motion.first_frame + motion.frames - 1
    if not (f0 <= first < last <= f1):
        raise ValueError(f"the range {first}..{last} must lie within the motion's frames {f0}..{f1}, first < last")
    return first - f0, last - f0


@dataclass(frozen=True)
class Step:
    """One step of a pipeline: an interpolator, "median3", or a smoothing filter (with ``size``)
    over frames ``first`` .. ``last`` of the chosen joints (all if None)."""

    kind: str
    first: int
    last: int
    joints: tuple[str, ...] | None = None
    size: int = 3

    def apply(self, motion: Motion) -> Motion:
        if self.kind in INTERPOLATORS:
            return interpolate(motion, self.first, self.last, self.kind, self.joints)
        if self.kind == "median3":
            return median3(motion, self.first, self.last, self.joints)
        if self.kind in FILTERS:
            a, b = _rows(motion, self.first, self.last)
            piece = motion.replace(values=motion.values[a : b + 1], first_frame=self.first)
            smoothed = filter_motion(piece, self.kind, self.size, self.joints)
            values = motion.values.copy()
            values[a : b + 1] = smoothed.values
            values.flags.writeable = False
            return motion.replace(values=values)
        raise ValueError(f"step kind must be one of {', '.join(STEPS)}, got {self.kind!r}")


@dataclass(frozen=True)
class Pipeline:
    """Steps applied in order, each to the result of the one before (the inputs are untouched)."""

    steps: tuple[Step, ...] = ()

    def then(self, kind: str, first: int, last: int, joints: Sequence[str] | None = None, size: int = 3) -> Pipeline:
        step = Step(kind, first, last, None if joints is None else tuple(joints), size)
        if kind not in STEPS:
            raise ValueError(f"step kind must be one of {', '.join(STEPS)}, got {kind!r}")
        return Pipeline((*self.steps, step))

    def apply(self, motion: Motion) -> Motion:
        for step in self.steps:
            motion = step.apply(motion)
        return motion
