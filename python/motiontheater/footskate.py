"""Footskate cleanup (Kovar, Schreiner & Gleicher, SCA 2002): feet that should stand still, do.

Given a motion and its footplants (detected, or a table the user edited:
:mod:`motiontheater.contacts`), each planted heel and ball is held at one
target per plant, on the floor; the legs and the root are adjusted frame by
frame, analytically, to reach them; the adjustments fade in and out around
the plants.  Only the root's translation and the legs' joints change: every
other channel of the result is the input's, bit for bit, and so is every leg
channel of a frame that needed no change.

The phases (the per-frame work is one C kernel, ``mt_footskate``):

1. Targets: a point planted at the frame before keeps its target; a new
   plant's target is the point's mean position over the plant, put on the
   floor at the point's resting clearance; when the foot's other point is
   planted too, the new target is set at the foot's heel-to-ball length from
   the other's, so that the foot keeps its shape.
2. Ankles: both points planted, the foot turns by the smallest rotation that
   takes its heel -> ball onto the targets' (its roll about that axis kept)
   and the ankle follows the heel target; one point planted, the foot keeps
   its turn and the ankle is moved by that point's (target - position).
   Turns and moves fade to nothing over ``blend`` seconds on either side of a
   constraint (the foot turning about the planted point where one still is).
3. Root: where a planted leg cannot reach its ankle target (the knee bent
   less than ``knee_soft`` degrees, or than the input's knee, if straighter),
   the root moves by the least that lets it (projection onto the sphere of
   reach, or onto two spheres' intersection); those moves are smoothed over
   ``root_window`` seconds so that the root does not pop, and what is still
   short after smoothing is moved per frame.
4. Legs: two-bone IK per leg: the knee bends or straightens about its hinge
   so that hip -> ankle has the target's length (never past straight), the
   hip turns the leg onto the target, the ankle takes the foot's turn.
   Joints with fewer than three rotation channels (the CMU knee has one, the
   CMU ankle two) take the nearest rotation they can: a one-channel knee is
   a hinge about its axis; a two-channel joint turns its segment exactly
   where asked and gives up the roll about it (then the ankle target is
   re-aimed twice so the planted point still lands); a joint with three
   takes any rotation, as Euler angles in its own channel order, each the
   nearest to the input's value.  No leg is stretched: bone lengths stay the
   skeleton's.
5. Floor: a foot planted nowhere whose heel or ball would go below the floor
   is lifted (the ankle target raised, the leg solved again); toe tips below
   the floor bend the toes up.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

import numpy as np

from mtcore import footskate as kernels

from .contacts import Contacts, Thresholds, detect_contacts, plant_targets
from .legs import Ground, LegArrays, Legs, fit_ground, leg_arrays, resolve_legs
from .motion import Motion

ContactsSource = "Contacts | str | os.PathLike | None"


@dataclass(frozen=True, eq=False)
class Cleanup:
    """A cleanup's result and what it stood on: the cleaned ``motion``, the ``contacts`` it
    enforced, the ``ground``, the root's ``root_offsets`` (frames, 3) in file units and the
    ``targets`` (legs, frames, 2, 3) the heel and ball were held at (NaN where not planted)."""

    motion: Motion
    contacts: Contacts
    ground: Ground
    legs: Legs
    root_offsets: np.ndarray
    targets: np.ndarray

    def root_rms(self, meters: bool = True) -> float:
        """Root-mean-square length of the root's change over the frames (metres, or file units)."""
        if not len(self.root_offsets):
            return 0.0
        rms = float(np.sqrt(np.mean(np.sum(self.root_offsets**2, axis=-1))))
        return rms * self.motion.skeleton.meters_per_unit if meters else rms


def _contacts(
    contacts, motion: Motion, arrays: LegArrays, ground: Ground, mpu: float, thresholds: Thresholds
) -> Contacts:
    if contacts is None:
        return detect_contacts(arrays, ground, motion.frame_rate, mpu, motion.first_frame, thresholds)
    if isinstance(contacts, (str, os.PathLike)):
        return Contacts.read_csv(contacts, first_frame=motion.first_frame, frames=motion.frames)
    if not isinstance(contacts, Contacts):
        raise TypeError(f"contacts must be a Contacts table, a CSV path or None, got {type(contacts).__name__}")
    if (contacts.first_frame, contacts.frames) != (motion.first_frame, motion.frames):
        last = contacts.first_frame + contacts.frames - 1
        raise ValueError(
            f"the contacts are for frames {contacts.first_frame}..{last}, the take has frames "
            f"{motion.first_frame}..{motion.first_frame + motion.frames - 1}: they are for another take"
        )
    return contacts


def prepare(
    motion: Motion,
    *,
    legs=None,
    up: str | None = None,
    floor: float | None = None,
    meters_per_unit: float | None = None,
) -> tuple[Legs, LegArrays, Ground, float]:
    """The legs, their arrays and the ground of a motion, and its metres per file unit."""
    mpu = motion.skeleton.meters_per_unit if meters_per_unit is None else float(meters_per_unit)
    if not (mpu > 0 and math.isfinite(mpu)):
        raise ValueError(f"meters_per_unit must be a positive number, got {meters_per_unit!r}")
    found = resolve_legs(motion.skeleton, legs)
    arrays = leg_arrays(motion, found, up=up, meters_per_unit=mpu)
    found = arrays.legs
    ground = fit_ground(arrays, motion.frame_rate, mpu, up=up, floor=floor)
    return found, arrays, ground, mpu


def clean_footskate(
    motion: Motion,
    contacts=None,
    *,
    legs=None,
    up: str | None = None,
    floor: float | None = None,
    meters_per_unit: float | None = None,
    blend: float = 0.2,
    root_window: float = 0.1,
    knee_soft: float = 3.0,
    thresholds: Thresholds = Thresholds(),
) -> Cleanup:
    """Footskate cleanup of a motion, with what it stood on (see :class:`Cleanup` and the
    module docstring); :func:`cleanup_footskate` returns the motion alone.

    - ``contacts``: the footplants (a :class:`~motiontheater.contacts.Contacts`
      table or its CSV file); default: detected (:func:`~motiontheater.contacts.detect_contacts`).
    - ``legs``: hip,knee,ankle[,toe] joints of the left then the right leg (default: found by name).
    - ``up``: the up axis ("y", "z", "-y"...); default y for ASF, detected for BVH.
    - ``floor``: the floor's level along up, file units; default fitted (tilted) to the feet at rest.
    - ``meters_per_unit``: default the skeleton's (give it for BVH, whose files do not say).
    - ``blend``: seconds over which adjustments fade in and out around constraints;
      ``root_window``: seconds of smoothing of the root's moves; ``knee_soft``: degrees short
      of straight that a knee keeps unless the input's is straighter.

    Raises ValueError (with UnknownNameError and FormatError among its kinds)
    naming what is wrong: no recognisable legs, contacts of another take, a
    floor above the character, a root without translation channels.
    """
    for name, value in (("blend", blend), ("root_window", root_window), ("knee_soft", knee_soft)):
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0):
            raise ValueError(f"{name} must be a number >= 0, got {value!r}")
    root_columns = _root_translation(motion)
    found, arrays, ground, mpu = prepare(motion, legs=legs, up=up, floor=floor, meters_per_unit=meters_per_unit)
    table = _contacts(contacts, motion, arrays, ground, mpu, thresholds)
    masks = table.masks(found)
    targets = plant_targets(masks, arrays.points)
    options = kernels.CleanupOptions(
        up=tuple(map(float, ground.up)),
        slope=tuple(map(float, ground.slope)),
        level=float(ground.level),
        blend=int(round(blend * motion.frame_rate)),
        root_window=int(round(root_window * motion.frame_rate / 2)),
        knee_soft=math.radians(knee_soft),
    )
    angles, root, enforced = kernels.cleanup(
        arrays.chains, arrays.hips, arrays.parents, arrays.angles, arrays.points, masks, targets, ground.clearance, options
    )
    values = motion.values.copy()
    changed = angles != arrays.angles  # unchanged angles keep their channel's bits
    used = arrays.columns >= 0
    for i in range(len(found)):
        for r in range(4):
            for n in range(3):
                column = arrays.columns[i, r, n]
                if column < 0:
                    continue
                rows = changed[i, :, r, n]
                values[rows, column] = angles[i, rows, r, n] / arrays.angle_scale
    del used
    for axis, column in enumerate(root_columns):
        moved = root[:, axis] != 0
        values[moved, column] += root[moved, axis]
    values.flags.writeable = False
    return Cleanup(motion.replace(values=values), table, ground, found, root, enforced)


def cleanup_footskate(motion: Motion, contacts=None, **options) -> Motion:
    """The motion with its footskate cleaned up: :func:`clean_footskate`'s motion."""
    return clean_footskate(motion, contacts, **options).motion


def _root_translation(motion: Motion) -> list[int]:
    order = motion.skeleton.dofs("root")
    missing = [d for d in ("tx", "ty", "tz") if d not in order]
    if missing:
        raise ValueError(
            f"the root has no {', '.join(missing)} channel: footskate cleanup moves the root and needs all three"
        )
    return motion.columns("root", ("tx", "ty", "tz"))
