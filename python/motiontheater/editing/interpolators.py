"""Interpolators over frame ranges (the CS838 interpolators) and the 3-frame median "cut" filter.

An interpolator replaces the frames strictly between two key frames A and B
by interpolating the keys.  Rotation interpolators work on joints with three
rotation channels, through unit quaternions (:func:`mtcore.rotations.interpolate_euler`,
one C pass per Euler convention for all joints and frames at once); other
channels interpolate linearly.  Each is a registered step (``slerp``,
``euler``, ``expmap``, ``aligned_expmap``, ``median3``), so they stack in a
:class:`~motiontheater.editing.pipeline.Pipeline`.
"""

from __future__ import annotations

from typing import Annotated

import numpy as np

from mtcore import median_filter1d
from mtcore import rotations as rot

from ..model.motion import Motion
from ..model.registry import Joints, register

INTERPOLATORS = {
    "slerp": "interpolate rotations along the shorter arc between the keys (SLERP)",
    "euler": "interpolate the stored Euler angles linearly between the keys",
    "expmap": "interpolate exponential maps (rotation vectors) linearly between the keys",
    "aligned_expmap": "interpolate exponential maps between the keys, the first flipped to take the short way",
}


def interpolate(
    motion: Motion,
    method: str = "slerp",
    *,
    frames: Annotated[tuple[int, int], "the key frames A:B; the frames between them are replaced"],
    joints: Annotated[Joints, "joints to interpolate (default: all)"] = None,
) -> Motion:
    """A new motion whose frames strictly between the key frames A and B interpolate the keys.

    The interpolators (``method``): slerp (quaternions, the short arc),
    euler (linear on the stored angles), expmap (linear on exponential
    maps) and aligned_expmap (the first key flipped to the second key's
    hemisphere, so that it too takes the short way).  Joints with other than three
    rotation channels, and every translation, interpolate linearly.  The
    Euler angles written continue from the first key (no 360-degree jumps).
    """
    if method not in INTERPOLATORS:
        raise ValueError(f"method must be one of {', '.join(INTERPOLATORS)}, got {method!r}")
    a, b = _keys(motion, frames)
    skeleton = motion.skeleton
    columns = skeleton.columns_of(joints)
    groups = [] if method == "euler" else skeleton.euler_groups(joints)
    turned = {int(c) for _, _, cols in groups for c in cols.ravel()}
    linear = [c for c in columns if c not in turned]
    values = motion.values.copy()
    t = (np.arange(a + 1, b) - a) / (b - a)
    values[a + 1 : b, linear] = values[a, linear] + t[:, None] * (values[b, linear] - values[a, linear])
    degrees = skeleton.angle_unit == "deg"
    for order, extrinsic, cols in groups:
        first = values[a, cols]
        # of the equivalent Euler triples, each frame's nearest the one before, from the first key on
        values[a + 1 : b, cols] = rot.interpolate_euler(
            first, values[b, cols], t, order, extrinsic=extrinsic, degrees=degrees, blend=method, start=first
        )
    values.flags.writeable = False
    return motion.replace(values=values)


def median3(
    motion: Motion,
    *,
    joints: Annotated[Joints, "joints to filter (default: all)"] = None,
) -> Motion:
    """The 3-frame median "cut" filter of CS838 on the stored values (edges held).

    Unlike the ``median`` step it does not unwrap angles first: it is the
    editor's quick fix for single-frame glitches, on the numbers as stored.
    Give ``frames`` to filter a range only.
    """
    columns = motion.skeleton.columns_of(joints)
    values = motion.values.copy()
    values[:, columns] = median_filter1d(values[:, columns], 3, axis=0, mode="nearest")
    values.flags.writeable = False
    return motion.replace(values=values)


def _keys(motion: Motion, frames: tuple[int, int]) -> tuple[int, int]:
    """The rows of the key frames; ValueError unless they lie in the motion, the first before the last."""
    first, last = frames
    if not motion.first_frame <= first < last <= motion.last_frame:
        raise ValueError(
            f"the key frames {first}:{last} must lie within the motion's frames "
            f"{motion.first_frame}..{motion.last_frame}, the first before the last"
        )
    return first - motion.first_frame, last - motion.first_frame


for _method, _summary in INTERPOLATORS.items():
    register(_method, interpolate, _summary, frames="own", fixed={"method": _method})
register("median3", median3, "the CS838 3-frame median filter on the stored values")
