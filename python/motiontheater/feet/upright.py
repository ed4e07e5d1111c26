"""Which way is up in a take: what the viewer, the renders and the feet's floor stand on.

A rest pose does not tell it: game rigs and Rokoko draw theirs along x, some exports lie down,
and y-up BVH files and z-up ones use the same grammar.  The frames do: over a take, a person's
hips are above their ankles.  Where no legs are found by name, the axis (y or z) along which the
frames span most is up, as :func:`~motiontheater.model.units.size_up_poses` finds it for the
unit.  ASF/AMC is y-up by Acclaim's convention.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.motion import Motion
from ..model.rig import pose_up, sampled_view
from .legs import axis_name, parse_up, resolve_legs


@dataclass(frozen=True)
class Up:
    """A take's up axis (``axis``: "y", "-z", ...) and why it is taken as up (``reason``)."""

    axis: str
    reason: str

    @property
    def vector(self) -> np.ndarray:
        """The axis as a unit vector."""
        return parse_up(self.axis)

    @property
    def turn(self) -> np.ndarray:
        """The rotation (3 x 3, det 1) that stands the take along +y, as the viewer and renders draw."""
        return np.array(_TURNS[self.axis], dtype=float)


_TURNS = {  # per up axis, a turn that takes it to +y
    "y": ((1, 0, 0), (0, 1, 0), (0, 0, 1)),
    "z": ((1, 0, 0), (0, 0, 1), (0, -1, 0)),
    "x": ((0, -1, 0), (1, 0, 0), (0, 0, 1)),
    "-y": ((1, 0, 0), (0, -1, 0), (0, 0, -1)),
    "-z": ((1, 0, 0), (0, 0, -1), (0, 1, 0)),
    "-x": ((0, 1, 0), (-1, 0, 0), (0, 0, 1)),
}


def take_up(motion: Motion, up: str | None = None) -> Up:
    """The up axis of a take: ``up`` where given ("y", "-z"...; ValueError naming what is
    accepted otherwise), else as the module docstring says."""
    if up is not None:
        return Up(axis_name(parse_up(up)), "given")
    if motion.skeleton.convention != "bvh":
        return Up("y", "ASF/AMC is y-up by Acclaim's convention")
    if not motion.frames:
        return Up(pose_up(motion), "the rest pose spans most along it (the take has no frames)")
    view = sampled_view(motion)
    poses = view.positions()
    try:
        legs = resolve_legs(view.skeleton)
    except ValueError:
        legs = None
    if legs is not None:
        rise = (poses[:, legs.points[:, 0]] - poses[:, legs.points[:, 2]]).reshape(-1, 3)
        rise = rise[np.isfinite(rise).all(axis=1)]
        if len(rise) and np.any(mean := rise.mean(axis=0)):
            return Up(axis_name(mean), f"the hips are above the ankles along it in {_frames(len(poses))}")
    return Up(pose_up(motion), f"no legs found by name; {_frames(len(poses))} span most along it")


@dataclass(frozen=True)
class Facing:
    """Where a take faces: ``axis`` ("z", "-x", ...; None where nothing tells), and why (``reason``)."""

    axis: str | None
    reason: str


TRAVEL = 0.5  # metres from the first frame to the last: a take that goes somewhere faces its way


def take_forward(motion: Motion, up: Up | None = None) -> Facing:
    """The horizontal axis a take faces: the way its body travels from the first frame to the last
    where it goes :data:`TRAVEL` or more, else the way its feet point (ankles to balls, legs found
    by name), else None.  ``up``: the take's (default :func:`take_up`'s)."""
    up = take_up(motion) if up is None else up
    if not motion.frames:
        return Facing(None, "the take has no frames")
    view = sampled_view(motion)
    poses = view.positions()
    vertical = up.vector

    def level(v: np.ndarray) -> np.ndarray:
        return v - np.outer(v @ vertical, vertical) if v.ndim > 1 else v - (v @ vertical) * vertical

    travel = level(poses[-1, 0] - poses[0, 0])
    metres = float(np.linalg.norm(travel)) * motion.skeleton.meters_per_unit
    if np.isfinite(metres) and metres >= TRAVEL:
        return Facing(axis_name(travel), f"the body travels {metres:.3g} m along it from the first frame to the last")
    try:
        legs = resolve_legs(view.skeleton)
    except ValueError:
        legs = None
    if legs is not None:
        toes = level((poses[:, legs.points[:, 3]] - poses[:, legs.points[:, 2]]).reshape(-1, 3))
        toes = toes[np.isfinite(toes).all(axis=1)]
        if len(toes) and np.any(mean := toes.mean(axis=0)):
            return Facing(axis_name(mean), f"the feet point along it (it travels {metres:.2g} m)")
    return Facing(None, f"it travels {metres:.2g} m and no feet are found by name")


def _frames(count: int) -> str:
    return f"{count} frame" if count == 1 else f"{count} frames"
