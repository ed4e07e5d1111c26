"""Footskate cleanup (Kovar, Schreiner & Gleicher, SCA 2002): feet that should stand still, do.

Given a motion and its footplants (detected, or a table the user edited:
:mod:`motiontheater.feet.contacts`), each planted heel and ball is held at one
target per plant, on the floor; the legs and the root are adjusted frame by
frame, analytically, to reach them; the adjustments fade in and out around
the plants.  Only the root's translation and the legs' joints change: every
other channel of the result is the input's, bit for bit, and so is every leg
channel of a frame that needed no change.

The phases (the per-frame work is C, :mod:`mtcore.footskate`):

1. Targets.  A point planted at the frame before keeps its target; a new
   plant's target is the point's mean position over the plant, put on the
   floor at the point's resting clearance; when the foot's other point is
   planted too (or was, a moment before: a roll from heel to ball), the new
   target is set at the foot's heel-to-ball length from the other's, so that
   the foot keeps its shape.
2. Ankles.  Both points planted: the foot turns by the smallest rotation
   that takes its heel -> ball onto the targets' (its roll about that axis
   kept) and the ankle follows the heel target.  One point planted: the foot
   keeps its turn (and turns up about the planted point if the other would
   go below the floor) and the ankle follows the planted point.  Turns and
   moves fade to nothing over ``blend`` seconds on either side of a
   constraint.
3. Root.  Where a leg cannot reach its ankle target with the knee bent at
   least ``knee_soft`` degrees (or as little as the input's knee, if
   straighter) and half as much as the input's knee, the root moves by the
   least that lets it: a projection onto the sphere of reach, or onto two
   spheres' intersection.  The moves are smoothed over ``root_window``
   seconds so that the root does not pop, and what is still short after
   smoothing is moved frame by frame.
4. Legs.  Two-bone IK per leg: the knee bends about its hinge so that hip ->
   ankle has the target's length (never past straight, to the side it bends
   in the take), the hip turns the leg onto the target, the ankle takes the
   foot's turn.  A joint takes the nearest rotation its channels allow: a
   one-channel knee (CMU's tibia: rx) is a hinge about its channel's axis; a
   knee with more channels bends about the take's mean bend axis; a
   two-channel joint (CMU's foot: rx rz) turns its segment exactly where asked
   and gives up the roll about it (the ankle target is then re-aimed once so
   that the planted point lands, to a few micrometres); a three-channel
   joint takes any rotation, as Euler angles in its own channel order, each
   the nearest to the input's.  No bone is stretched: the skeleton's lengths
   stay, the root moves instead.
5. Floor.  A foot planted nowhere whose heel or ball would go below the
   floor is lifted (smoothly, by the upper envelope of its depths), the leg
   solved again; toe tips below the floor bend the toes up.
"""

from __future__ import annotations

import math
import os
import warnings
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Literal

import numpy as np

from mtcore import footskate as kernels
from mtcore.kinematics import Kinematics

from ..model import units
from ..model.motion import Motion
from ..model.registry import Frames, Joints, step
from ..model.rig import body_view
from .contacts import DEFAULT, Contacts, Plant, Thresholds, detect_contacts, plant_targets
from .legs import Ground, LegArrays, Legs, fit_ground, leg_arrays, resolve_legs

UP_AXES = ("x", "y", "z", "-x", "-y", "-z")


@dataclass(frozen=True, eq=False)
class Cleanup:
    """A cleanup's result and what it stood on.

    ``motion`` is the cleaned motion; ``contacts`` the footplants enforced;
    ``ground`` the floor and the contact points' clearances; ``legs`` the legs
    (their heels derived where the skeleton has none); ``root_offsets``
    (frames, 3) what was added to the root's translation, file units;
    ``targets`` (legs, frames, 2, 3) where each heel and ball was held (NaN
    where not planted); ``meters_per_unit`` the unit of both.
    """

    motion: Motion
    contacts: Contacts
    ground: Ground
    legs: Legs
    root_offsets: np.ndarray
    targets: np.ndarray
    meters_per_unit: float

    def root_rms_mm(self) -> float:
        """Root-mean-square length of the root's change over the frames, in millimetres."""
        if not len(self.root_offsets):
            return 0.0
        return float(np.sqrt(np.mean(np.sum(self.root_offsets**2, axis=-1)))) * self.meters_per_unit * 1000


def prepare(
    motion: Motion,
    *,
    legs: Legs | Joints = None,
    up: str | None = None,
    floor: float | None = None,
    meters_per_unit: float | None = None,
    kinematics: Kinematics | None = None,
) -> tuple[LegArrays, Ground, float]:
    """A motion's legs as arrays, its ground, and its metres per file unit (the skeleton's, or
    ``meters_per_unit``).  ``legs``: resolved :class:`~motiontheater.feet.legs.Legs` (so that a
    cleaned motion is measured with the heels of its input), joint names, or None to find them.
    The motion is seen from its body (:func:`~motiontheater.model.rig.body_view`): a static joint
    above the hips and position channels that only hold offsets are not the legs' concern.
    ``kinematics``: the motion's forward kinematics, where the caller has them (used where the
    motion is its own body view)."""
    view = body_view(motion).motion
    if view is not motion:
        kinematics = None
    motion = view
    if meters_per_unit is None and motion.skeleton.length_source == "assumed":
        warnings.warn(
            f"the take's length unit is assumed ({units.label(motion.skeleton.length_unit)}): its size tells "
            f"none, so the footplants' thresholds in metres may not fit; give it with --unit UNIT (Python: "
            f"read it with unit=UNIT), UNIT: {units.UNIT_HELP}",
            UserWarning,
            stacklevel=3,
        )
    mpu = motion.skeleton.meters_per_unit if meters_per_unit is None else float(meters_per_unit)
    if not (mpu > 0 and math.isfinite(mpu)):
        raise ValueError(f"meters_per_unit must be a positive number, got {meters_per_unit!r}")
    found = legs if isinstance(legs, Legs) else resolve_legs(motion.skeleton, legs)
    if found.skeleton.joint_names != motion.skeleton.joint_names:
        raise ValueError("the legs given are of another skeleton than the motion's")
    _require_finite_legs(motion, found)
    arrays = leg_arrays(motion, found, up=up, meters_per_unit=mpu, kinematics=kinematics)
    return arrays, fit_ground(arrays, motion.frame_rate, mpu, up=up, floor=floor), mpu


def _require_finite_legs(motion: Motion, legs: Legs) -> None:
    """ValueError unless some frame holds every channel that places the legs (the root's, the
    legs' and the joints' between them) as a number: a take of NaN has no feet to plant."""
    skeleton = motion.skeleton
    columns = skeleton.derived(("leg columns", legs.rotators.tobytes()), lambda: _placing_columns(motion, legs))
    values = motion.values
    # nearly every take's first frame is whole: no need to look at (or gather) the others
    if len(values) and not (np.isfinite(values[0, columns]).all() or np.isfinite(values[:, columns]).all(axis=1).any()):
        raise ValueError(
            "no frame holds the legs as numbers (their channels are NaN or inf in every frame): there are "
            "no feet to measure or plant; fill the gaps first (the fill_gaps step)"
        )


def _placing_columns(motion: Motion, legs: Legs) -> list[int]:
    """The columns of the legs' joints and the joints above them."""
    skeleton, joints = motion.skeleton, set()
    for index in legs.rotators.ravel():
        if index < 0:
            continue
        joint = skeleton.joint_names[index]
        while joint not in joints:
            joints.add(joint)
            if joint == "root":
                break
            joint = skeleton.parent(joint)
    return [c for joint in joints for c in motion.columns(joint)]


def contacts_of(
    contacts: Contacts | str | os.PathLike | None,
    motion: Motion,
    arrays: LegArrays,
    ground: Ground,
    meters_per_unit: float,
    thresholds: Thresholds = DEFAULT,
) -> Contacts:
    """The footplants of a motion: ``contacts`` given (a table, or its CSV file, checked to be
    of this take), else detected."""
    if contacts is None:
        return detect_contacts(arrays, ground, motion.frame_rate, meters_per_unit, motion.first_frame, thresholds)
    if isinstance(contacts, (str, os.PathLike)):
        table = Contacts.read_csv(contacts, first_frame=motion.first_frame, frames=motion.frames)
    elif isinstance(contacts, Contacts):
        table = contacts
    else:
        raise TypeError(f"contacts must be a Contacts table, a CSV file or None, got {type(contacts).__name__}")
    table.check_take(motion.first_frame, motion.frames)
    table.masks(arrays.legs)  # every foot named is one of the legs'
    return table


def clean_footskate(
    motion: Motion,
    contacts: Contacts | str | os.PathLike | None = None,
    *,
    legs: Legs | Joints = None,
    up: str | None = None,
    floor: float | None = None,
    meters_per_unit: float | None = None,
    blend: float = 0.2,
    root_window: float = 0.1,
    knee_soft: float = 3.0,
    thresholds: Thresholds = DEFAULT,
    workers: int | None = None,
    frames: tuple[int, int] | None = None,
    plants: Iterable[Plant] = (),
) -> Cleanup:
    """Footskate cleanup of a motion, with what it stood on (see :class:`Cleanup` and the
    module docstring); the step ``cleanup`` (``motion.cleanup(...)``, ``motiontheater
    cleanup``) returns the motion alone.

    - ``contacts``: the footplants (a :class:`~motiontheater.feet.contacts.Contacts`
      table or its CSV file); default: detected with ``thresholds``.
    - ``legs``: hip,knee,ankle[,toe] joints of the left then the right leg (default: found by name).
    - ``up``: the up axis ("y", "z", "-y"...); default y for ASF, detected for BVH.
    - ``floor``: the floor's level along up, file units (then level); default: fitted, tilted, to
      the feet at rest.
    - ``meters_per_unit``: default the skeleton's length unit (an ASF's ``:units length``, a
      BVH's detected from its size, or as read with ``unit=`` / ``--unit``).
    - ``blend``: seconds over which adjustments fade in and out around constraints;
      ``root_window``: seconds of smoothing of the root's moves; ``knee_soft``: degrees short
      of straight that a constrained knee keeps unless the input's is straighter.
    - ``workers``: threads for the two legs (None: both on takes of 1,000 frames or more; 1: the
      calling thread only).
    - ``frames``: (first, last) frame numbers: only the plants within them are held and only
      those frames change (the take check's recipes give a range ``blend`` seconds wider than
      the plants, so that the adjustments fade within it); default: all.
    - ``plants``: footplants to hold besides the table's (those the take check found sliding,
      which detection, holding no point faster than 0.45 m/s, may not plant).

    Raises ValueError (UnknownNameError and FormatError among its kinds) naming
    what is wrong: no recognisable legs, contacts of another take, a floor
    above the character, a root without translation channels.
    """
    for name, value in (("blend", blend), ("root_window", root_window), ("knee_soft", knee_soft)):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value < 0:
            raise ValueError(f"{name} must be a number >= 0, got {value!r}")
    if knee_soft >= 90:
        raise ValueError(f"knee_soft must be below 90 degrees, got {knee_soft}")
    if up is not None and (not isinstance(up, str) or up.strip().lower().lstrip("+") not in UP_AXES):
        raise ValueError(f"up must be one of {', '.join(UP_AXES)}, got {up!r}")
    given, view = motion, body_view(motion)
    motion = view.motion
    root_columns = _root_translation(motion, view.body)
    arrays, ground, mpu = prepare(motion, legs=legs, up=up, floor=floor, meters_per_unit=meters_per_unit)
    table = contacts_of(contacts, motion, arrays, ground, mpu, thresholds)
    plants = tuple(plants)
    if plants:
        table = Contacts([*table.plants, *plants], table.first_frame, table.frames, table.frame_rate)
        table.masks(arrays.legs)  # every foot named is one of the legs'
    rows = _rows(motion, frames)
    if frames is not None:
        masks = _within(table.masks(arrays.legs), rows, axis=1)
        table = Contacts.from_masks(masks, arrays.legs, motion.first_frame, motion.frame_rate)
    masks = table.masks(arrays.legs)
    options = kernels.CleanupOptions(
        up=(float(ground.up[0]), float(ground.up[1]), float(ground.up[2])),
        slope=(float(ground.slope[0]), float(ground.slope[1]), float(ground.slope[2])),
        level=float(ground.level),
        blend=round(blend * motion.frame_rate),
        root_window=round(root_window * motion.frame_rate / 2),
        knee_soft=math.radians(knee_soft),
    )
    angles, root, enforced = kernels.cleanup(
        arrays.chains,
        arrays.hips,
        arrays.parents,
        arrays.angles,
        arrays.points,
        masks,
        plant_targets(masks, arrays.points),
        ground.clearance,
        options,
        workers=workers,
    )
    values = kernels.write_channels(
        motion.values, arrays.angles, angles, arrays.columns, arrays.angle_scale, root, root_columns
    )
    values.flags.writeable = False
    cleaned = view.restore(motion.replace(values=values))
    if frames is not None:  # the floor's lifts outside the range are not asked for, nor the
        # last bits of the body view's round trip
        values = _within(cleaned.values, rows, given.values)
        values.flags.writeable = False
        cleaned, root = cleaned.replace(values=values), _within(root, rows)
    return Cleanup(cleaned, table, ground, arrays.legs, root, enforced, mpu)


@step("cleanup", "footskate cleanup: planted heels and balls held still on the floor (Kovar et al. 2002)", frames="own")
def cleanup(
    motion: Motion,
    *,
    contacts: Annotated[Path | None, "footplants CSV (foot,point,first,last; default: detected)"] = None,
    floor: Annotated[float | None, "the floor's level along the up axis, file units (default: fitted)"] = None,
    up: Annotated[
        Literal["x", "y", "z", "-x", "-y", "-z"] | None,
        "the up axis (default: y for ASF/AMC; for BVH found from the frames, as info says)",
    ] = None,
    legs: Annotated[Joints, "hip,knee,ankle[,toe] of the left then the right leg (default: found by name)"] = None,
    blend: Annotated[float, "seconds over which adjustments fade in and out around plants"] = 0.2,
    knee_soft: Annotated[float, "degrees short of straight that a constrained knee keeps"] = 3.0,
    frames: Annotated[
        Frames, "hold the plants within frames FIRST..LAST only and change no other frame (default: all)"
    ] = None,
    plants: Annotated[
        tuple[str, ...] | None, "plants to hold besides those detected, each FOOT:heel|ball:FIRST:LAST (frame numbers)"
    ] = None,
) -> Motion:
    """Hold planted feet still on the floor: every planted heel and ball at one target per plant,
    the legs solved analytically and the root moved where a leg cannot reach.

    Only the root's translation and the legs' joints change. The footplants are
    detected from height and speed unless --contacts gives a table (motiontheater
    contacts writes one to edit). The floor is fitted to the resting feet (tilted
    as the capture's is) unless --floor gives its level. See
    motiontheater.feet.footskate for the method.
    """
    return clean_footskate(
        motion,
        contacts,
        legs=legs,
        up=up,
        floor=floor,
        blend=blend,
        knee_soft=knee_soft,
        frames=frames,
        plants=[_plant(text) for text in plants or ()],
    ).motion


def _plant(text: str) -> Plant:
    """A plant written FOOT:POINT:FIRST:LAST (the foot's name may hold colons: Mixamo's do)."""
    parts = str(text).rsplit(":", 3)
    usage = f"a plant is FOOT:heel|ball:FIRST:LAST (frame numbers), got {text!r}"
    if len(parts) != 4 or not all(p.strip().lstrip("-").isdigit() for p in parts[2:]):
        raise ValueError(usage)
    try:
        return Plant(parts[0], parts[1], int(parts[2]), int(parts[3]))
    except ValueError as error:
        raise ValueError(f"{usage}: {error}") from None


def _rows(motion: Motion, frames: tuple[int, int] | None) -> slice:
    """The rows of frames first..last (frame numbers), checked to be the motion's."""
    if frames is None:
        return slice(0, motion.frames)
    if not motion.first_frame <= frames[0] <= frames[1] <= motion.last_frame:
        raise ValueError(
            f"frames {frames[0]}:{frames[1]} are not within the motion's frames {motion.first_frame}..{motion.last_frame}"
        )
    return slice(frames[0] - motion.first_frame, frames[1] - motion.first_frame + 1)


def _within(a: np.ndarray, rows: slice, outside: np.ndarray | None = None, axis: int = 0) -> np.ndarray:
    """``a`` at ``rows`` of its frame ``axis``; elsewhere ``outside`` (default zero, False)."""
    out = np.zeros_like(a) if outside is None else outside.copy()
    index = (slice(None),) * axis + (rows,)
    out[index] = a[index]
    return out


def _root_translation(motion: Motion, body: str = "root") -> list[int]:
    order = motion.skeleton.dofs("root")
    missing = [d for d in ("tx", "ty", "tz") if d not in order]
    if missing:
        joint = "the root" if body == "root" else f"the body joint '{body}'"
        raise ValueError(
            f"{joint} has no {', '.join(missing)} channel: footskate cleanup moves the body and needs all three"
        )
    return motion.columns("root", ("tx", "ty", "tz"))
