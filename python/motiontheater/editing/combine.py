"""The motion combiner of MotionTheater (thesis ch. 4.2): a new motion laid over an old one.

A piece of the new motion (``cut``) is laid onto frames of the result
(``scale``), cross-faded with the old motion at its borders (``blend``),
kept continuous at the root (``preserve``), applied to chosen joints only,
and its repeated frames re-interpolated.  Python works out the borders,
depths and the frame map (:func:`plan`); the per-frame loop is C
(:func:`mtcore.combine.combine_frames`).  Frame numbers, not indices, as in
the thesis.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np

from mtcore import rotations as rot
from mtcore.combine import combine_frames

from ..model.errors import UnknownNameError
from ..model.motion import Motion
from ..model.rig import body_view, pose_up
from ..model.skeleton import TRANSLATIONS

PRESERVE = (None, "literal", "ground")
ROTATION_BLENDS = ("slerp", "linear")
UP_AXES = ("x", "y", "z")


@dataclass(frozen=True)
class Border:
    """A border of the piece where it meets old frames: at its start (g1) or end (g2)."""

    side: str  # "start" or "end"
    frame: int  # g1 or g2
    left: int  # blend frames before (start: old side) or up to (end: piece side) the border
    right: int
    step: float  # the weight step of the cross-fade, 1 / (left + right + 2)

    @property
    def window(self) -> tuple[int, int] | None:
        """First and last frame of the cross-fade, or None when there is none."""
        if self.left == self.right == 0:
            return None
        return (self.frame - self.left, self.frame + self.right)


@dataclass(frozen=True, eq=False)
class Plan:
    """Which frames of the old and new motions every output frame takes, and how.

    ``frames`` are the output frame numbers; ``cut`` the new motion's frames the piece shows; ``old_row``/``new_row`` the rows
    of ``old.values``/``new.values`` they read (-1 for none), ``weight`` the
    new motion's share, ``next_row``/``ramp`` the re-interpolation of repeated
    frames.  ``piece`` is the output range the cut lands on, ``source`` the
    new motion's frames it reads (blend extensions included), ``borders``
    the cross-fades, ``gap`` the frames between old and piece.
    """

    frames: np.ndarray
    old_row: np.ndarray
    new_row: np.ndarray
    next_row: np.ndarray | None
    ramp: np.ndarray | None
    weight: np.ndarray
    piece: tuple[int, int]
    cut: tuple[int, int]
    source: tuple[int, int]
    borders: tuple[Border, ...]
    gap: tuple[int, int] | None
    blend: int
    preserve: str | None
    blend_rows: np.ndarray  # indices of the output frames that are cross-faded

    def describe(self) -> str:
        """The frame map and borders in words (``motiontheater combine --dry-run``)."""
        lines = [
            f"output frames {self.frames[0]}..{self.frames[-1]}" if len(self.frames) else "no output frames",
            f"piece {self.piece[0]}..{self.piece[1]} from source frames {self.cut[0]}..{self.cut[1]}"
            + (
                f" (the blends also read source frames {self.source[0]}..{self.source[1]})"
                if self.source != self.cut
                else ""
            ),
        ]
        for b in self.borders:
            window = b.window
            lines.append(
                f"{b.side} border at {b.frame}: "
                + (
                    f"blend {window[0]}..{window[1]} (depth {b.left} + {b.right}, step 1/{round(1 / b.step)})"
                    if window
                    else "no blend"
                )
            )
        if self.gap:
            lines.append(
                f"gap {self.gap[0]}..{self.gap[1]}: "
                + ("smooth transition" if self.blend else "holds the last pose before it")
            )
        if self.preserve:
            lines.append(f"root preserved ({self.preserve})")
        return "\n".join(lines)


def _half_up(numerator, denominator):
    """numerator / denominator rounded to the nearest integer, halves up (exact, integers)."""
    return (2 * numerator + denominator) // (2 * denominator)


def _pair(value, name: str) -> tuple[int, int] | None:
    if value is None:
        return None
    try:
        first, last = (int(v) for v in value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a pair of frame numbers (first, last), got {value!r}") from None
    if (first, last) == (0, 0):  # the thesis's "not set"
        return None
    return first, last


def plan(
    old: Motion,
    new: Motion,
    *,
    cut=None,
    scale=None,
    blend: int = 0,
    preserve: str | None = None,
    discard_old: bool = False,
    interpolate: bool = False,
) -> Plan:
    """The frame map of :func:`combine` (see there for the arguments)."""
    if new.skeleton.channels != old.skeleton.channels:
        raise ValueError("new: a motion of another skeleton (its channels differ from the old motion's)")
    if new.frame_rate != old.frame_rate:
        raise ValueError(
            f"new: a motion at {_hz(new.frame_rate)} and the old one at {_hz(old.frame_rate)}: frames would not "
            f"keep their times; resample it first (motion.resample(rate={_hz(old.frame_rate, unit='')}), "
            f"motiontheater resample --rate {_hz(old.frame_rate, unit='')})"
        )
    n1, n2 = new.first_frame, new.first_frame + new.frames - 1
    o1, o2 = old.first_frame, old.first_frame + old.frames - 1
    cut, scale = _pair(cut, "cut"), _pair(scale, "scale")
    cf, ct = cut or (n1, n2)
    if new.frames == 0 or not n1 <= cf <= ct <= n2:
        raise ValueError(f"cut=({cf}, {ct}) is outside the new motion's frames {n1}..{n2}")
    if scale is not None and scale[0] >= scale[1]:
        raise ValueError(f"scale=({scale[0]}, {scale[1]}) needs its first frame before its last")
    sf, st = scale or (cf, ct)
    if isinstance(blend, bool) or not isinstance(blend, (int, np.integer)) or blend < 0:
        raise ValueError(f"blend must be a depth of 0 frames or more, got {blend!r}")
    if preserve not in PRESERVE:
        raise ValueError(f"preserve must be one of {PRESERVE}, got {preserve!r}")
    if blend and preserve:
        warnings.warn(
            "blend and preserve exclude each other: blending is off (blend=0), the root is preserved", stacklevel=3
        )
        blend = 0
    old_present = not discard_old and old.frames > 0

    def source(i):
        """Source frame of output frame(s) i: cf + (i - sf) / (st - sf) * (ct - cf), halves up."""
        if st == sf:
            return np.full_like(i, cf) if isinstance(i, np.ndarray) else cf
        return _half_up(cf * (st - sf) + (i - sf) * (ct - cf), st - sf)

    borders = []
    start_depth = end_depth = (0, 0)
    if old_present and blend and o1 <= sf - 1 <= o2:
        needed = source(sf - blend)
        depth = blend if needed >= n1 else _half_up((cf - n1) * blend, cf - needed)
        start_depth = (min(depth, sf - o1), min(blend, o2 - sf, st - sf))
    if old_present and blend and o1 <= st + 1 <= o2:
        needed = source(st + blend)
        depth = blend if needed <= n2 else _half_up((n2 - ct) * blend, needed - ct)
        end_depth = (
            min(blend, st - o1, st - sf - start_depth[1] - 1 if start_depth != (0, 0) else st - sf),
            min(depth, o2 - st),
        )
        end_depth = (max(end_depth[0], 0), end_depth[1])
    for side, frame, (left, right) in (("start", sf, start_depth), ("end", st, end_depth)):
        if old_present and (o1 <= frame - 1 <= o2 if side == "start" else o1 <= frame + 1 <= o2):
            borders.append(Border(side, frame, left, right, 1.0 / (left + right + 2)))

    first, last = (sf, st) if not old_present else (min(o1, sf), max(o2, st))
    count = last - first + 1
    frames = np.arange(first, last + 1, dtype=np.int64)

    def at(frame: int) -> int:
        return frame - first  # output frames are consecutive: index arithmetic, no masks

    weight = np.zeros(count)
    weight[at(sf) : at(st) + 1] = 1.0
    if old_present:  # each output frame's old row, held at the ends: one pass
        old_row = np.concatenate(
            [
                np.zeros(max(0, o1 - first), np.int64),
                np.arange(max(0, first - o1), min(old.frames, last - o1 + 1), dtype=np.int64),
                np.full(max(0, last - o2), old.frames - 1, np.int64),
            ]
        )
    else:
        old_row = np.full(count, -1, np.int64)
    lo, hi = sf, st  # the frames that read the new motion: piece, blends, gap
    gap, gap_pose = None, None
    if old_present and sf > o2 + 1:  # the piece after the old motion
        gap, gap_pose = (o2 + 1, sf - 1), sf
        k = np.arange(1, sf - o2)
        weight[at(gap[0]) : at(gap[1]) + 1] = k / (sf - o2) if blend else 0.0
        lo = gap[0] if blend else sf
    elif old_present and st < o1 - 1:  # the piece before the old motion
        gap, gap_pose = (st + 1, o1 - 1), st
        k = np.arange(1, o1 - st)
        weight[at(gap[0]) : at(gap[1]) + 1] = 1.0 - k / (o1 - st) if blend else 1.0
        hi = gap[1]
    blends = [np.arange(at(gap[0]), at(gap[1]) + 1)] if gap and blend else []
    for border in borders:
        if border.window is None:
            continue
        w0, w1 = border.window
        rise = np.arange(1, w1 - w0 + 2) * border.step
        weight[at(w0) : at(w1) + 1] = rise if border.side == "start" else 1.0 - rise
        blends.append(np.arange(at(w0), at(w1) + 1))
        lo, hi = min(lo, w0), max(hi, w1)

    x = frames[at(lo) : at(hi) + 1] - sf  # source frames of lo..hi, in place: halves up
    if st == sf:
        x[:] = cf
    else:
        x *= ct - cf
        x += cf * (st - sf)
        x *= 2
        x += st - sf
        x //= 2 * (st - sf)
    if gap is not None and gap_pose is not None:
        x[at(max(gap[0], lo)) - at(lo) : at(min(gap[1], hi)) - at(lo) + 1] = source(gap_pose)
    new_row = np.full(count, -1, np.int64)
    x -= n1
    new_row[at(lo) : at(hi) + 1] = np.clip(x, 0, new.frames - 1, out=x)
    x += n1
    next_row = ramp = None
    if interpolate and st - sf > ct - cf:
        next_row, ramp = new_row.copy(), np.zeros(count)
        piece = slice(at(sf), at(st) + 1)
        _ramps(new_row[piece], next_row[piece], ramp[piece])
    return Plan(
        frames=frames,
        old_row=old_row,
        new_row=new_row,
        next_row=next_row,
        ramp=ramp,
        weight=weight,
        piece=(sf, st),
        cut=(cf, ct),
        source=(int(x.min()), int(x.max())),
        borders=tuple(borders),
        gap=gap,
        blend=blend,
        preserve=preserve,
        blend_rows=np.concatenate(blends) if blends else np.zeros(0, np.int64),
    )


def _ramps(rows: np.ndarray, next_row: np.ndarray, ramp: np.ndarray) -> None:
    """Runs of repeated source rows in the piece become linear ramps towards the next source row
    (written into next_row and ramp, views of the piece)."""
    if len(rows) < 2:
        return
    starts = np.flatnonzero(np.r_[True, rows[1:] != rows[:-1]])
    lengths = np.diff(np.r_[starts, len(rows)])
    for_run = np.repeat(np.arange(len(starts)), lengths)
    position = np.arange(len(rows)) - starts[for_run]
    has_next = for_run + 1 < len(starts)
    next_row[:] = np.where(has_next, rows[starts[np.minimum(for_run + 1, len(starts) - 1)]], rows)
    ramp[:] = np.where(has_next, position / lengths[for_run], 0.0)


def _hz(rate: float, unit: str = " Hz") -> str:
    return f"{rate:.6g}{unit}"


def combine(old: Motion, new: Motion, **options: Any) -> Motion:
    """Lay ``new`` over ``old``: a new Motion (the inputs are not modified).

    - ``cut=(cf, ct)``: use frames cf..ct of ``new`` (default all of it).
    - ``scale=(sf, st)``: lay the piece onto frames sf..st; output frame i takes
      source frame cf + (i - sf) / (st - sf) * (ct - cf), halves rounded up.
      Without it the piece keeps its frame numbers.
    - ``blend=b``: cross-fade over g-b..g+b where the piece meets old frames
      (weights in steps of 1 / (2b + 2)), with the depth cut down on either
      side to the frames the old and new motions have, the new side's depth
      rescaled as in the thesis (eq. 4.18-4.19).  Between motions that do not
      touch, b > 0 fills the gap with a transition, b = 0 holds the last pose.
    - ``preserve``: keep the root continuous at the borders.  "literal" is the
      thesis's rule (the root's stored translation and rotation at g1-1 are
      added to the piece, taken relative to its first frame, and at g2 to
      the frames after it); "ground" moves the following trajectory rigidly on
      the ground plane and turns it about the ``up`` axis, so position and
      heading continue.  Blend and preserve exclude each other: both warns,
      and the blend is dropped.
    - ``joints``: only these joints' channels take the new motion.
    - ``discard_old``: the result is the piece alone.
    - ``interpolate``: where the piece is scaled longer than its source, runs
      of repeated frames become linear ramps to the next source frame.
    - ``rotation_blend``: "slerp" (quaternions, for joints with three rotation
      channels) or "linear" on the stored Euler angles (the thesis).
    - ``up``: the vertical axis for "ground" ("x", "y" or "z"; default: y for ASF/AMC, for BVH
      the one the old take's poses stand along, :func:`~motiontheater.model.rig.pose_up`).
    - ``workers``: threads, as for the filters.
    Raises ValueError naming the argument at fault.  The options and their
    defaults are those of :func:`combine_planned` and :func:`plan`.
    """
    return combine_planned(old, new, **options)[1]


def combine_planned(
    old: Motion,
    new: Motion,
    *,
    joints: Iterable[str] | None = None,
    rotation_blend: str = "slerp",
    up: str | None = None,
    workers: int | None = None,
    **frame_map: Any,
) -> tuple[Plan, Motion]:
    """:func:`combine`, returning the frame map it followed as well; the options that make the
    frame map (cut, scale, blend, preserve, discard_old, interpolate) are :func:`plan`'s.

    Takes of a game rig are combined as their bodies
    (:func:`~motiontheater.model.rig.body_view`): the root preserved is the joint that
    carries the body, not a static joint above it."""
    seen = body_view(old)
    if not seen.identity and new.skeleton.channels == old.skeleton.channels:
        p, result = combine_planned(
            seen.motion,
            body_view(new).motion,
            joints=joints,
            rotation_blend=rotation_blend,
            up=up,
            workers=workers,
            **frame_map,
        )
        return p, seen.restore(result)
    if rotation_blend not in ROTATION_BLENDS:
        raise ValueError(f"rotation_blend must be one of {ROTATION_BLENDS}, got {rotation_blend!r}")
    up = pose_up(old) if up is None else up
    if up not in UP_AXES:
        raise ValueError(f"up must be one of {UP_AXES}, got {up!r}")
    skeleton = old.skeleton
    discard_old = frame_map.get("discard_old", False)
    chosen = skeleton.joint_names if joints is None or discard_old else tuple(joints)
    chosen = tuple("root" if skeleton.is_root(joint) else joint for joint in chosen)
    for joint in chosen:
        if not skeleton.has_joint(joint):
            raise UnknownNameError(f"joints: no joint '{joint}' in skeleton '{skeleton.name}'")
    p = plan(old, new, **frame_map)
    selected = np.zeros(len(skeleton.channels), np.uint8)
    for joint in chosen:
        selected[old.columns(joint)] = 1
    offset_row, offsets, offset_channels = None, None, ()
    if p.preserve and "root" in chosen and not discard_old:
        offset_row, offsets, offset_channels = _root_offsets(old, new, p, up)
    values = combine_frames(
        None if discard_old else old.values,
        new.values,
        p.old_row,
        p.new_row,
        p.weight,
        next_row=p.next_row,
        ramp=p.ramp,
        selected=selected,
        offset_row=offset_row,
        offsets=offsets,
        offset_channels=offset_channels,
        workers=workers,
    )
    if rotation_blend == "slerp":
        _slerp_blends(values, old, new, p, chosen)
    values.flags.writeable = False
    return p, old.replace(values=values, first_frame=int(p.frames[0]) if len(p.frames) else 1)


def _slerp_blends(values: np.ndarray, old: Motion, new: Motion, p: Plan, joints: Iterable[str]) -> None:
    """Cross-faded frames of the joints with three rotation channels, again, by SLERP: one C pass
    per Euler convention for all joints and frames, each angle then the whole turns nearest the
    linear blend already in ``values``."""
    frames = p.blend_rows
    if not len(frames):
        return
    skeleton = old.skeleton
    u = p.weight[frames]
    degrees = skeleton.angle_unit == "deg"
    rows = (slice(None), None, None)  # (frames,) indices against (joints, 3) columns
    for order, extrinsic, columns in skeleton.euler_groups(joints):
        a = old.values[p.old_row[frames][rows], columns]
        b = new.values[p.new_row[frames][rows], columns]
        if p.ramp is not None and p.next_row is not None:
            b = b + p.ramp[frames][rows] * (new.values[p.next_row[frames][rows], columns] - b)
        where = (frames[rows], columns)
        values[where] = rot.interpolate_euler(
            a, b, u, order, extrinsic=extrinsic, degrees=degrees, reference=values[where]
        )


def _nearest_equivalent(angle: np.ndarray, reference: np.ndarray, period: float) -> np.ndarray:
    """angle plus the multiple of period that brings it closest to reference."""
    return angle + period * np.round((reference - angle) / period)


def _root_rotations(old: Motion) -> tuple[list[int], str, bool]:
    """The root's rotation columns, their Euler order and whether it is extrinsic (ASF) or not (BVH)."""
    groups = old.skeleton.euler_groups(["root"])
    if not groups:
        raise ValueError("preserve='ground' needs a root with three rotation channels")
    order, extrinsic, columns = groups[0]
    return columns[0].tolist(), order, extrinsic


def _root_offsets(old: Motion, new: Motion, p: Plan, up: str):
    """(offset_row, offsets, channels): what to add to the root channels of each output frame
    so that the root continues at each border.  The piece (with any gap frames that hold its
    pose) is moved to continue from the old frame before it, and the old frames after it to
    continue from the moved piece."""
    o1, o2 = old.first_frame, old.first_frame + old.frames - 1
    sf, st = p.piece
    first = int(p.frames[0])
    end = p.gap[1] if p.gap and st < o1 else st  # the last frame that holds the piece
    before = sf - 1 if o1 <= sf - 1 <= o2 else (o2 if o2 < sf else None)
    after = end + 1 if o1 <= end + 1 <= o2 else None
    root = np.array(old.columns("root"))

    def raw(lo: int, hi: int) -> np.ndarray:
        """Root channels of output frames lo..hi as combined, before any preserving
        (rows and columns gathered together: only the root's columns are read)."""
        i = slice(lo - first, hi - first + 1)
        uses_new = p.weight[i] > 0
        if uses_new.all():
            return new.values[p.new_row[i][:, None], root]
        if not uses_new.any():
            return old.values[p.old_row[i][:, None], root]
        return np.where(
            uses_new[:, None],
            new.values[np.maximum(p.new_row[i], 0)[:, None], root],
            old.values[np.maximum(p.old_row[i], 0)[:, None], root],
        )

    def old_root(frame: int) -> np.ndarray:
        return old.values[frame - o1, root]

    offset_row = np.full(len(p.frames), -1, np.int64)
    piece_rows, follow_rows = slice(sf - first, end - first + 1), slice(end + 1 - first, len(p.frames))
    if p.preserve == "literal":
        shift = old_root(before) - raw(sf, sf)[0] if before is not None else np.zeros(len(root))
        rows = [shift]
        offset_row[piece_rows] = 0
        if after is not None:
            rows.append(raw(end, end)[0] + shift - old_root(after))
            offset_row[follow_rows] = 1
        return offset_row, np.array(rows), root.tolist()
    piece = raw(sf, end)
    moved = _ground_moved(old, piece, piece[0], old_root(before), up) if before is not None else piece
    tables = [moved - piece]
    offset_row[piece_rows] = np.arange(len(piece))
    if after is not None:
        follow = raw(end + 1, int(p.frames[-1]))
        tables.append(_ground_moved(old, follow, follow[0], moved[-1], up) - follow)
        offset_row[follow_rows] = len(piece) + np.arange(len(follow))
    return offset_row, np.concatenate(tables), root.tolist()


def _forward_axis(turns: np.ndarray, up: int) -> int:
    """The root's own axis whose heading is the take's: z, else x, else y, the first that lies
    within 60 degrees of the ground plane over the take's root rotations (frames, 3, 3).  Chosen
    by the frames, not the world's up alone, so that a take turned by a static root (a z-up
    export) is spliced with the turn it has y-up."""
    tilt = np.nanmean(np.abs(turns[:, up, :]), axis=0) if len(turns) else np.zeros(3)
    return next((k for k in (2, 0, 1) if tilt[k] < 0.5), 2 if up != 2 else 0)


def _ground_moved(motion: Motion, rows: np.ndarray, start: np.ndarray, anchor: np.ndarray, up: str) -> np.ndarray:
    """Root channel rows moved rigidly so that ``start`` lands on ``anchor``: translated on the
    ground plane, turned about the ``up`` axis to the anchor's heading."""
    skeleton = motion.skeleton
    order = skeleton.root.order
    t_cols = [order.index(d) for d in TRANSLATIONS if d in order]
    rot_cols, axes, extrinsic = _root_rotations(motion)
    root_columns = list(motion.columns("root"))
    r_cols = [root_columns.index(c) for c in rot_cols]
    degrees = skeleton.angle_unit == "deg"
    u = "xyz".index(up)
    ground = [i for i in range(3) if i != u]

    def matrices(angles: np.ndarray) -> np.ndarray:
        return rot.euler_to_matrices(angles, axes, extrinsic=extrinsic, degrees=degrees)

    forward = _forward_axis(matrices(motion.values[:, rot_cols]), u)

    def heading(row: np.ndarray) -> float:
        m = matrices(row[r_cols])
        # the angle about up, right-handed: from axis u+1 towards axis u+2 (z to x about y, x to y about z)
        return math.atan2(m[(u + 2) % 3, forward], m[(u + 1) % 3, forward])

    turn = heading(anchor) - heading(start)
    spin = rot.rotvecs_to_matrices(np.eye(3)[u] * turn)
    out = rows.copy()
    if len(t_cols) == 3:
        position = rows[:, t_cols] - start[t_cols]
        moved = position @ spin.T
        moved[:, u] = position[:, u] + start[t_cols][u]  # heights keep their own values
        for g in ground:
            moved[:, g] += anchor[t_cols][g]
        out[:, t_cols] = moved
    # the turn about the up axis comes after the root's own rotation, about a fixed axis
    angles = rot.matrices_to_euler(spin @ matrices(rows[:, r_cols]), axes, extrinsic=extrinsic, degrees=degrees)
    period = skeleton.period
    out[:, r_cols] = _nearest_equivalent(np.unwrap(angles, period=period, axis=0), rows[:, r_cols], period)
    return out
