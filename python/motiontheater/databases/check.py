"""The take check: what is wrong with a take, where, how badly, and the steps that repair it.

One C pass over the channels (:func:`mtcore.check.channel_events`) lists the candidates: runs of
NaN, held values, samples far from their neighbours' median, jumps and repeated frames.  This
module judges them as a person would, in physical units: a spike in an Euler channel is a spike
only if the joint's rotation leaves its neighbours (near gimbal lock the angles swing while the
rotation does not); a jump of the angles with no jump of the rotation is a flip; a jump of the
root that no runner makes is a teleport; a held value is frozen only where the channel moves
around it.  Every limit is stated in degrees, metres, seconds and Hz below and converted with
the skeleton's length unit and the take's frame rate.  The legs (skating and sinking feet, the
floor, knees bent backwards) are judged in :mod:`.check_feet`, elbows bent backwards in
:mod:`.check_arms`.

Each finding carries the steps that fix it, confined to its frames and joints (see
:func:`recipe`): missing, spiked, frozen and repeated frames are dropped and filled from the
frames around them (``fill_gaps``), flips unrolled (``unroll``), a unit off by a known factor
rescaled (``scale``), jitter low-passed (``butterworth`` at Winter's cut-off), skating feet held
(``cleanup`` over their frames).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike

from mtcore import check as kernel
from mtcore import median_filter1d
from mtcore.kinematics import Kinematics, world_kinematics
from mtcore.rotations import euler_to_quaternions, slerp, unroll_euler

from ..editing.pipeline import Pipeline
from ..formats.cut import Cut
from ..model.motion import Motion
from ..model.rig import body_joint
from ..model.skeleton import ROTATIONS, TRANSLATIONS, Skeleton
from ..model.units import HUMAN_HEIGHT
from ..model.vectors import lengths
from . import check_arms, check_feet
from .check_arms import arm_findings
from .check_feet import leg_findings
from .check_pace import dropped_findings
from .findings import Finding
from .pieces import check_frames
from .workspace import Workspace, lent

SPIKE_DEG = 5.0
"""Degrees a joint's rotation must leave the median of the five frames around it to be a spike."""
SPIKE_M = 0.02
"""Metres a position channel must leave the median of the five frames around it to be a spike."""
PEAK_ACCELERATION_DEG = 20_000.0
"""deg/s^2: at low rates a smooth turn of this acceleration leaves its neighbours' median by
a dt^2 / 2, and the spike limit grows to that (5 degrees at 120 Hz, 11 at 30 Hz)."""
PEAK_ACCELERATION_M = 60.0
"""m/s^2: the same for positions."""
JUMP_DEG = 10.0
"""Degrees a frame's change of angle must differ from the changes beside it to be a jump."""
FLIP_DEG = 90.0
"""Degrees by which unrolled Euler angles must differ from the file's for a frame to be flipped."""
LEAD_FRAMES = 3
"""A take whose every frame after its first few is flipped from them has those first frames
flipped (a rest pose before the capture), not the rest."""
RUN_SPEED = 12.0
"""m/s: faster than any sprinter (12.4 m/s is the fastest measured): a root moving faster has
teleported, or the unit or rate is wrong."""
FROZEN_SECONDS = 0.1
"""The shortest run of one held value that can be frozen."""
FROZEN_DEG, FROZEN_M = 2.0, 0.01
"""How far the channel would have moved over the run, at its speed around it, to be frozen."""
JITTER_DEG, JITTER_M = 0.5, 0.002
"""The noise level (standard deviation of white noise) that is jitter, and twice it medium."""
SMOOTH_ACCELERATION_DEG = 3_000.0
"""deg/s^2: the RMS acceleration of smooth motion, whose residual at low rates is not noise."""
BONE_DRIFT_M, BONE_DRIFT_SHARE = 0.02, 0.05
"""A bone with position channels drifts when its length leaves its median by both of these."""
FILL_SECONDS = 0.5
"""The longest run the recipes fill by interpolation; longer ones are reported, not invented."""
STEP_PAIR_SECONDS = 0.05
"""An opposite jump within this time after a jump brings a channel back: a pop, not a jump
(longer excursions are motion as often as not), or within POP_FRAMES frames at low rates."""
POP_FRAMES = 3
TELEPORT_M = 0.25
"""Metres: a root that leaves its neighbours by this for a few frames has teleported, however slow."""
SEEN_M = 0.03
"""Metres the points a joint turns must leave their path for a turn to be plain to see: a spike or
jump of a rotation is high only if it moves them so far (a thumb flipped over moves its tip 4-9
cm; a twist of the hand that moves the fingers 2 cm, nobody sees)."""
UNSEEN_M = 0.005
"""Metres below which a rotation's spike or jump moves nothing drawn (a hand whose end site has no
length, a bone turned about itself): at most medium, which a skinned mesh would show."""
SPIKE_TURN_DEG_S = 3_000.0
"""deg/s: a high spike turns faster than this between two frames, into it or out of it (a fast
wrist at 30 Hz turns 1,800 deg/s through a smooth excursion; a pop turns 170 deg in one frame)."""


@dataclass(frozen=True)
class _Channel:
    index: int
    joint: str
    dof: str

    @property
    def turns(self) -> bool:
        return self.dof in ROTATIONS

    @property
    def name(self) -> str:
        return f"{self.joint} {self.dof}"


class _Take:
    """A take as the detectors see it: its channels, units and rate."""

    def __init__(self, motion: Motion, name: str, space: Workspace | None = None):
        self.motion = motion
        self.space = Workspace() if space is None else space  # where the kinematics go
        self.name = name
        self.rate = motion.frame_rate
        self.dt = 1.0 / motion.frame_rate
        skeleton = motion.skeleton
        self.meters = skeleton.meters_per_unit
        self.degrees = 1.0 if skeleton.angle_unit == "deg" else 180.0 / math.pi  # degrees per file unit
        self.root = body_joint(motion)  # the joint that carries the body (a static root above it is no body)
        self.channels, self.triples, self._columns = skeleton.derived("check channels", lambda: _channels(skeleton))
        # the joints whose rotation channels make a rotation (one, two or three of them): their
        # rotations are judged, not their angles (a thumb's rz that crosses 90 deg and comes back
        # 180 deg on is a turn, with no other pair of angles for it)
        self.rotating = skeleton.derived("check rotations", lambda: _rotations(skeleton))
        self.turning = skeleton.derived("check turning channels", lambda: _turning(self.channels))
        # each channel's joint, and its joint's rotation or position channels, numbered in the
        # order of their names (the order events are joined in)
        self.joints, self.kinds = skeleton.derived("check channel groups", lambda: _groups(self.channels))
        self.joint_of = skeleton.derived("check channel joints", lambda: _joint_indices(skeleton, self.channels))
        self._quaternions: dict[str, np.ndarray] = {}
        self._turns: dict[tuple[str, int], np.ndarray] = {}
        # the joints whose world rotations the detectors read (:attr:`held`): the legs' and arms',
        # and those of the joints with spikes or steps (:meth:`keep`)
        self._turned = set(skeleton.derived("check turned joints", lambda: _turned_joints(skeleton)))
        # the turning spikes that what they move settles (:func:`_settled`), by id: (finding,
        # first row, last row, degrees, high by their angles)
        self.unsettled: dict[int, tuple[Finding, int, int, float, bool]] = {}
        self.begins, self.ends = True, True  # whether these frames begin and end the take

    def keep(self, joints: Iterable[int]) -> None:
        """Keep the world rotations of these joints (indices) too, before :attr:`held` is first read."""
        if "held" in self.__dict__:  # worked out already: these joints' rotations would be missing
            raise RuntimeError("world rotations are kept before the take's kinematics are first read")
        self._turned.update(joints)

    @cached_property
    def held(self) -> Kinematics:
        """The joints' places and the world rotations kept (:meth:`keep`), for the spikes, steps,
        legs and arms alike (a piece's at most): world rotations are most of what forward
        kinematics writes, and the detectors read a few joints'."""
        tree, frames = self.motion.skeleton.tree, self.motion.frames
        turned = sorted(self._turned)
        out = (
            self.space.array("positions", (frames, tree.joints, 3)),
            self.space.array("world", (frames, len(turned), 3, 3)),
        )
        return world_kinematics(self.motion.values, tree, turned=turned, workers=1, out=out)

    def frame(self, row: int) -> int:
        return self.motion.first_frame + int(row)

    def physical(self, channel: _Channel, value: float) -> float:
        """A value of the channel in degrees or metres."""
        return value * (self.degrees if channel.turns else self.meters)

    def columns(self, joint: str, turns: bool) -> np.ndarray:
        """The joint's rotation (or position) channels' columns."""
        return self._columns.get((joint, turns), _NONE)

    def gaps(self, joint: str) -> bool:
        """Whether the joint's channels miss values (NaN) anywhere."""
        return bool(np.isnan(self.motion.values[:, self.motion.columns(joint)]).any())

    def unit(self, channel: _Channel) -> str:
        return "deg" if channel.turns else "m"

    def quaternions(self, joint: str, rows: np.ndarray | slice) -> np.ndarray:
        """The joint's rotations at the rows, of every row made once (candidates ask for the
        rows around them again and again)."""
        made = self._quaternions.get(joint)
        if made is None:
            order, extrinsic, columns = self.rotating[joint]
            angles = np.zeros((self.motion.frames, 3))
            angles[:, : len(columns)] = self.motion.values[:, columns]  # the axes a joint lacks: turned by 0
            made = euler_to_quaternions(angles, order, extrinsic=extrinsic, degrees=self.degrees == 1.0)
            self._quaternions[joint] = made
        return made[rows]

    def turns(self, joint: str, apart: int = 1) -> np.ndarray:
        """The degrees the joint's rotation turns from each row to the row ``apart`` rows on
        ((rows - apart,): entry k from row k), every row's worked out once."""
        made = self._turns.get((joint, apart))
        if made is None:
            q = self.quaternions(joint, slice(None))
            made = self._turns[joint, apart] = _angle_deg(q[apart:], q[:-apart])
        return made

    def seen(self, runs: list[tuple[str, int, int]]) -> list[tuple[float, float]]:
        """For each run (joint, first row, last row; within the take, a row on either side): how
        far the joint's rotation over the rows puts out the points it turns, in metres: where they
        are, and where filling the joint alone would put them.  Where they are: the farthest any
        of them lies, at a row of the stretch, from midway between where it is in the rows before
        and after, twice that over a stretch of several rows (a pop stands out so by its size,
        the ends of a turn-over by half of it; smooth motion, however fast, by little; a turn
        that the joints below turn back, by nothing).  Where filling would put them: how far they
        lie from where the joint's rotation on the path between the rows around would put them,
        the joints below as they are (a hand whose end has no length turns nothing; a thigh
        turned about itself that the knee turns back looks right, and filling the thigh alone
        would put the leg out).  (0, 0) where it turns none.  Every run of a joint in one call
        of :func:`mtcore.check.seen_runs`."""
        out = [(0.0, 0.0)] * len(runs)
        for joint, members in _by_joint(joint for joint, _, _ in runs).items():
            if not len(self._points(joint)):
                continue
            off, filled = self._seen(joint, [runs[i][1] for i in members], [runs[i][2] for i in members])
            for i, a, b in zip(members, off.tolist(), filled.tolist()):
                out[i] = (a, b)
        return out

    def seen_jumps(self, jumps: list[tuple[str, int]]) -> list[tuple[float, float, float]]:
        """For each jump of a joint's rotation into row ``at`` (2 <= at <= rows - 2) that stays:
        how far it puts out the points the joint turns, in metres: the lesser of how much longer
        their step into the row is than twice their steps before and after it (a snap; an arm
        flung out fast at 30 Hz takes steps as long beside it), and how far they lie from where
        the rotation going on at its pace would put them; and, of the point that jumps most, its
        step into the row and the longer of its steps beside.  (0, 0, 0) where it turns no
        point.  Every jump of a joint at once."""
        out = [(0.0, 0.0, 0.0)] * len(jumps)
        for joint, members in _by_joint(joint for joint, _ in jumps).items():
            points = len(self._points(joint))
            if not points:
                continue
            at = np.array([jumps[i][1] for i in members])
            p = self._places(joint, (at[:, None] + np.arange(-2, 2)).ravel()).reshape(len(at), 4, points, 3)
            steps = lengths(np.diff(p, axis=1))  # into rows at - 1, at, at + 1
            steps[np.isnan(steps)] = 0.0
            beside = np.maximum(steps[:, 0], steps[:, 2])
            worst = np.argmax(steps[:, 1] - 2 * beside, axis=1)
            step, beside = (
                np.take_along_axis(steps[:, 1], worst[:, None], 1)[:, 0],
                np.take_along_axis(beside, worst[:, None], 1)[:, 0],
            )
            jumped = np.maximum(step - 2 * beside, 0.0)
            _, moved = self._seen(joint, at, at, (at - 2, at - 1))  # the rotation going on from the two rows before
            for i, a, b, c in zip(members, np.minimum(jumped, moved).tolist(), step.tolist(), beside.tolist()):
                out[i] = (a, b, c)
        return out

    def _seen(
        self, joint: str, first: ArrayLike, last: ArrayLike, keys: tuple[ArrayLike, ArrayLike] | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """:func:`mtcore.check.seen_runs` of the joint's runs (rows first..last), its rotation's
        SLERP between the rows ``keys`` (default those around each run)."""
        skeleton = self.motion.skeleton
        j = skeleton.joint_names.index(joint)
        return kernel.seen_runs(
            self.held.positions, self.held.world, j, self._origin(j), skeleton.tree.axis[j], self._points(joint),
            self.quaternions(joint, slice(None)), first, last, self.meters, keys, int(self.held.rows([j])[0]),
        )  # fmt: skip

    def _origin(self, j: int) -> int:
        """The joint whose place the offsets of the points joint j turns are taken from: its own
        in BVH (a joint's place is its parent's doing), its parent's end in ASF."""
        parent = int(self.motion.skeleton.tree.parent[j])
        return j if self.motion.skeleton.convention == "bvh" or parent < 0 else parent

    def _points(self, joint: str) -> np.ndarray:
        skeleton = self.motion.skeleton
        return skeleton.derived(("turned points", joint), lambda: _turned(skeleton, joint))

    def _places(self, joint: str, rows: np.ndarray) -> np.ndarray:
        """The places (rows, points, 3) in metres of the points the joint's rotation moves."""
        return self.held.positions[rows[:, None], self._points(joint)] * self.meters


_NONE = np.zeros(0, np.intp)


def _by_joint(joints: Iterable[str]) -> dict[str, list[int]]:
    """Where each joint stands in ``joints`` (the runs, jumps or pairs worked out a joint at once)."""
    out: dict[str, list[int]] = {}
    for i, joint in enumerate(joints):
        out.setdefault(joint, []).append(i)
    return out


def _turned(skeleton: Skeleton, joint: str) -> np.ndarray:
    """The points (indices of ``joint_names``) that the joint's rotation moves: those below it,
    and an ASF bone's own end."""
    parent = skeleton.tree.parent
    j = skeleton.joint_names.index(joint)
    bvh = skeleton.convention == "bvh"
    below = []
    for i in range(len(parent)):
        k = int(parent[i]) if bvh else i  # a BVH joint's own place is its parent's doing
        while k >= 0 and k != j:
            k = int(parent[k])
        if k == j:
            below.append(i)
    return np.array(below, dtype=np.intp)


def _channels(skeleton: Skeleton) -> tuple[list[_Channel], dict, dict[tuple[str, bool], np.ndarray]]:
    """The channels; the joints with three rotation channels, whose Euler angles may flip to
    another triple: joint -> (order, extrinsic, columns); and each joint's rotation and position
    columns: (joint, turns) -> columns."""
    channels = [_Channel(i, j, d) for i, (j, d) in enumerate(skeleton.channels)]
    triples = {
        skeleton.channels[int(row[0])][0]: (order, extrinsic, row)
        for order, extrinsic, columns in skeleton.euler_groups()
        for row in columns
    }
    grouped: dict[tuple[str, bool], list[int]] = {}
    for c in channels:
        grouped.setdefault((c.joint, c.turns), []).append(c.index)
    return channels, triples, {key: np.array(columns, dtype=np.intp) for key, columns in grouped.items()}


def _turning(channels: list[_Channel]) -> np.ndarray:
    """Which of the channels turn (read-only: every take of the skeleton shares it)."""
    out = np.array([c.turns for c in channels], dtype=bool)
    out.flags.writeable = False
    return out


def _rotations(skeleton: Skeleton) -> dict[str, tuple[str, bool, np.ndarray]]:
    """The joints whose one, two or three rotation channels make a rotation: joint -> (order,
    extrinsic, columns), the order of three axes that their channels' axes begin (those of a
    joint with fewer than three channels turned by 0)."""
    extrinsic = skeleton.convention != "bvh"
    out = {}
    for joint in skeleton.joint_names:
        start, dofs = skeleton.first_column(joint), skeleton.dofs(joint)
        turns = [(start + i, dof[1]) for i, dof in enumerate(dofs) if dof in ROTATIONS]
        axes = "".join(axis for _, axis in turns)
        order = axes + "".join(a for a in "xyz" if a not in axes)[: 3 - len(axes)]
        if 1 <= len(turns) <= 3 and order[0] != order[1] and order[1] != order[2]:
            out[joint] = (order, extrinsic, np.array([c for c, _ in turns], dtype=np.intp))
    return out


def _groups(channels: list[_Channel]) -> tuple[np.ndarray, np.ndarray]:
    """Per channel: the rank of its joint's name, and of (its joint's name, whether it turns)."""
    joints = sorted({c.joint for c in channels})
    kinds = sorted({(c.joint, c.turns) for c in channels})
    return (
        np.array([joints.index(c.joint) for c in channels], dtype=np.intp),
        np.array([kinds.index((c.joint, c.turns)) for c in channels], dtype=np.intp),
    )


def _joint_indices(skeleton: Skeleton, channels: list[_Channel]) -> np.ndarray:
    """Each channel's joint's index among the skeleton's joints."""
    index = {name: i for i, name in enumerate(skeleton.joint_names)}
    return np.array([index[c.joint] for c in channels], dtype=np.intp)


def _turned_joints(skeleton: Skeleton) -> list[int]:
    """The joints whose world rotations the legs' and arms' detectors read."""
    return check_feet.turned_joints(skeleton) + check_arms.turned_joints(skeleton)


def _angle_deg(q0: np.ndarray, q1: np.ndarray) -> np.ndarray:
    """The angle of the rotation between unit quaternions, in degrees."""
    p = q0 * q1  # summed as np.sum does, a third of its time (numpy reduces an axis of 4 slowly)
    dot = np.abs(p[..., 0] + p[..., 1] + p[..., 2] + p[..., 3])
    return np.degrees(2 * np.arccos(np.minimum(dot, 1.0)))


def _limits(take: _Take) -> tuple[np.ndarray, np.ndarray]:
    dt2 = take.dt**2
    spike_deg = max(SPIKE_DEG, PEAK_ACCELERATION_DEG * dt2 / 2)
    spike_m = max(SPIKE_M, PEAK_ACCELERATION_M * dt2 / 2)
    jump_deg = max(JUMP_DEG, PEAK_ACCELERATION_DEG * dt2)
    jump_m = RUN_SPEED * take.dt / math.sqrt(3)  # a jump of RUN_SPEED * dt in any direction shows on an axis
    spikes = np.where(take.turning, spike_deg / take.degrees, spike_m / take.meters)
    steps = np.where(take.turning, jump_deg / take.degrees, jump_m / take.meters)
    return spikes, steps


def check_motion(motion: Motion, take: str = "") -> list[Finding]:
    """Every finding of the take (named ``take`` in them), sorted by first frame, severity and
    kind; a long take checked a piece at a time (:mod:`.pieces`)."""
    return check_blocks(motion.replace(values=motion.values[:0]), [motion.values], take)


def check_blocks(template: Motion, blocks: Iterable[np.ndarray], take: str = "") -> list[Finding]:
    """:func:`check_motion` of the take whose frames come as ``blocks`` of rows, in order (a take
    read a piece at a time: :func:`~motiontheater.formats.amc.open_amc`), with ``template``'s
    skeleton, rate and first frame."""
    found = check_frames(template, blocks, lambda piece, begins, ends: _check_piece(piece, take, begins, ends))
    return sorted(found, key=lambda f: (f.first, -f.rank, f.kind, f.joints))


def _check_piece(motion: Motion, take: str, begins: bool, ends: bool) -> list[Finding]:
    """The findings of a piece of a take, ``begins`` and ``ends`` saying whether it begins and
    ends the take (a held pose at an end, a rest pose before the capture)."""
    # a number too large to write, read as infinity: a value missing, as NaN is (a finite sum
    # tells there is none at a fraction of the cost of looking at each)
    with np.errstate(over="ignore", invalid="ignore"):  # huge values may add up to infinity
        unsure = not np.isfinite(motion.values.sum())
    if unsure and np.isinf(motion.values).any():
        motion = motion.replace(values=np.where(np.isinf(motion.values), np.nan, motion.values))
    with lent() as space:
        return _piece_findings(_Take(motion, take, space), begins, ends)


def _piece_findings(t: _Take, begins: bool, ends: bool) -> list[Finding]:
    motion, take = t.motion, t.name
    t.begins, t.ends = begins, ends
    findings = _unit(t)
    for finding in findings:  # lengths are judged in the unit the fix makes them
        for name, options in finding.fix:
            t.meters *= options["factor"] if name == "scale" else 1.0
    if motion.frames:
        spikes, steps = _limits(t)
        rows = motion.frames
        min_run = max(3, round(FROZEN_SECONDS * t.rate))
        found = kernel.channel_events(motion.values, spikes, steps, min_run)
        by_kind = found.by_kind()
        # the joints whose spikes and steps are judged by what their rotations move (:meth:`_Take.seen`)
        t.keep(t.joint_of[by_kind[kernel.SPIKE][0][:, 0]].tolist() + t.joint_of[by_kind[kernel.STEP][0][:, 0]].tolist())
        repeats = by_kind[kernel.REPEAT][0]
        findings += _repeats(t, repeats, rows)
        findings += _gaps(t, *by_kind[kernel.GAP])
        flips = _flips(t, by_kind[kernel.STEP], by_kind[kernel.SPIKE])
        edges = {(f.joints[0], frame) for f in flips for frame in (f.first, f.last + 1)}
        findings += flips + _frozen(t, *by_kind[kernel.FROZEN], repeats, min_run, edges)
        # the jumps into and out of a flip, a hold or a gap are that finding's, not spikes of their
        # own: (joint, rotation or position, frame)
        explained = {
            (joint, turns, frame)
            for f in findings
            if f.kind in ("flip", "frozen", "gap")
            for joint in f.joints
            for turns in _turns_of(f)
            for frame in _edges_of(f)
        }
        findings += _spikes(t, by_kind[kernel.SPIKE], by_kind[kernel.STEP], explained, spikes)
        findings += _jitter(t, found.roughness, found.smooth_rows)
        dropped, findings = dropped_findings(motion, take, findings, t.held)
        findings += dropped
        findings += _bones(t)
        findings += _speed(t)
        findings += leg_findings(motion, take, t.meters, t.held)
        findings += arm_findings(motion, take, t.held)
    return findings


def _edges_of(finding: Finding) -> Iterable[int]:
    """The frames whose jumps a flip (its ends), a hold or a gap (all of it) explains."""
    if finding.kind == "flip":
        return (*range(finding.first - 1, finding.first + 2), *range(finding.last, finding.last + 3))
    return range(finding.first - 1, finding.last + 3)


def _turns_of(finding: Finding) -> tuple[bool, ...]:
    """Whether the channels a flip, hold or gap concerns turn (True), place (False) or both."""
    if finding.kind == "flip":
        return (True,)
    if finding.kind == "frozen" and finding.channel is not None:
        return (finding.channel.rsplit(" ", 1)[1] in ROTATIONS,)
    return (True, False)


def _fill(t: _Take, first_row: int, last_row: int, joints: Iterable[str] | None) -> tuple:
    """The fill_gaps step that drops rows first..last and fills them from the frames beside, or
    () where there is no frame on one side or the run is too long to invent."""
    count = last_row - first_row + 1
    if first_row < 1 or last_row >= t.motion.frames - 1 or count > FILL_SECONDS * t.rate:
        return ()
    options: dict = {
        "max_gap": math.ceil((count + 1) / t.rate * 1000) / 1000,
        "drop": [t.frame(first_row), t.frame(last_row)],
        "frames": [t.frame(first_row - 1), t.frame(last_row + 1)],
    }
    if joints is not None:
        options["joints"] = sorted(joints)
    return (("fill_gaps", options),)


def _joint_runs(
    t: _Take, events: np.ndarray, sizes: np.ndarray, pad: int = 0, apart: bool = True
) -> list[tuple[str, int, int, int, float]]:
    """Events of one kind joined per joint (its rotation channels apart from its position
    channels, unless not ``apart``) where their rows overlap (within ``pad``): (joint, first row, last row, worst
    channel, its size)."""
    out: list[list] = []
    order = np.lexsort((events[:, 1], (t.kinds if apart else t.joints)[events[:, 0]]))
    # as Python numbers: numpy's scalars cost more than the work
    for (c, first, last, *_), size in zip(events[order].tolist(), sizes[order].tolist()):
        joint = t.channels[c].joint
        kin = not apart or (bool(out) and t.channels[out[-1][3]].turns == t.channels[c].turns)
        if out and out[-1][0] == joint and kin and first <= out[-1][2] + pad:
            run = out[-1]
            run[2] = max(run[2], last)
            if abs(t.physical(t.channels[c], size)) > abs(t.physical(t.channels[run[3]], run[4])):
                run[3], run[4] = c, size
        else:
            out.append([joint, first, last, c, size])
    return [(r[0], r[1], r[2], r[3], r[4]) for r in out]


def _repeats(t: _Take, events: np.ndarray, rows: int) -> list[Finding]:
    out = []
    for _, first, last, _, _ in events.tolist():
        count = last - first + 1
        seconds = count / t.rate
        held = ((first <= 1 and t.begins) or (last >= rows - 1 and t.ends)) and seconds >= FILL_SECONDS
        severity = "low" if held else "medium"
        what = "the take starts or ends with a held pose" if held else "dropped frames filled by repeating one"
        out.append(
            Finding(
                t.name, "repeated", (), t.frame(first), t.frame(last), severity, round(seconds, 6), "s",
                f"{count} frame(s) ({seconds:.3g} s) equal to the frame before in every channel: {what}",
                fix=() if severity == "low" else _fill(t, first, last, None),
            )
        )  # fmt: skip
    return out


def _gaps(t: _Take, events: np.ndarray, sizes: np.ndarray) -> list[Finding]:
    out = []
    for joint, first, last, c, _ in _joint_runs(t, events, sizes, apart=False):
        seconds = (last - first + 1) / t.rate
        fix = _fill(t, first, last, [joint])
        severity = "high" if not fix else "medium"
        out.append(
            Finding(
                t.name, "gap", (joint,), t.frame(first), t.frame(last), severity, round(seconds, 6), "s",
                f"{joint}: {last - first + 1} frame(s) ({seconds:.3g} s) missing (NaN or infinite)"
                + ("" if fix else ", too long or at an end of the take to fill"),
                t.channels[c].name, fix,
            )
        )  # fmt: skip
    return out


def _frozen(
    t: _Take, events: np.ndarray, sizes: np.ndarray, repeats: np.ndarray, min_run: int, flips: set
) -> list[Finding]:
    if not len(events):
        return []
    values = t.motion.values
    rows = len(values)
    window = max(2, round(FROZEN_SECONDS * t.rate))
    repeated = np.zeros(rows, bool)
    for _, first, last, _, _ in repeats:
        repeated[first : last + 1] = True
    frozen: list[tuple] = []
    dead: dict[str, list[int]] = {}
    for (c, first, last, _, _), _size in zip(events, sizes):
        channel = t.channels[int(c)]
        if last - first + 1 < min_run or repeated[first + 1 : last + 1].all():
            continue
        if channel.turns and ({(channel.joint, t.frame(first)), (channel.joint, t.frame(last + 1))} & flips):
            continue  # a channel that holds still, flipped with its joint's triple
        if first == 0 and last == rows - 1:
            dead.setdefault(channel.joint, []).append(int(c))
            continue
        if np.count_nonzero(values[:, c] == values[first, c]) * 2 >= rows:
            continue  # where the channel rests most of the take (a hinge's off-axis, a joint limit)
        around = [values[max(first - window, 0) : first + 1, c], values[last : last + window + 1, c]]
        changes = [np.abs(np.diff(a)) for a in around if len(a) > 2]
        if not changes:
            continue
        moving = np.concatenate(changes)
        moving = moving[moving > 0]
        quantum = float(moving.min()) if len(moving) else 0.0
        # how far the channel would have gone at its speed on either side, or where it lands
        # when the hold lets go: a held value rejoins the motion with a jump
        speed = max(float(np.median(d)) for d in changes)
        beyond = [values[max(first - 3 - window, 0) : max(first - 3, 0), c], values[last + 4 : last + 4 + window, c]]
        if not any(len(b) > 1 and np.ptp(b) > 0 for b in beyond):
            continue  # still on both sides, but for a few frames at the hold's ends: a pop, not a hold
        after = values[last + 1 : last + 4, c]  # the least of three frames: a pop comes back
        leap = float(np.nan_to_num(np.abs(after - values[last, c])).min()) if len(after) else 0.0
        expected = max(speed * (last - first), leap)
        floor = FROZEN_DEG / t.degrees if channel.turns else FROZEN_M / t.meters
        if expected > max(5 * quantum, floor):
            frozen.append((int(c), int(first), int(last), kernel.FROZEN, int(first), expected))
    out = []
    table = np.array([f[:5] for f in frozen], dtype=np.intp).reshape(-1, 5)
    for joint, first, last, c, moved in _joint_runs(t, table, np.array([f[5] for f in frozen])):
        channel = t.channels[c]
        seconds = (last - first) / t.rate
        out.append(
            Finding(
                t.name, "frozen", (joint,), t.frame(first), t.frame(last),
                "high" if seconds > FILL_SECONDS else "medium", round(seconds, 6), "s",
                f"{channel.name} held for {seconds:.3g} s where it would move about "
                f"{t.physical(channel, moved):.3g} {t.unit(channel)} at its speed around the hold",
                channel.name, _fill(t, first + 1, last, [joint]),
            )
        )  # fmt: skip
    for joint, columns in dead.items():
        mine = t.motion.skeleton.columns_of([joint])
        if len(columns) < len(mine):  # the joint's other channels move
            names = ", ".join(t.channels[c].dof for c in columns)
            out.append(
                Finding(
                    t.name, "dead", (joint,), t.motion.first_frame, t.motion.last_frame, "low",
                    round(rows / t.rate, 6), "s",
                    f"{joint}: {names} never move{'s' if len(columns) == 1 else ''} while its other channels do",
                    t.channels[columns[0]].name,
                )
            )  # fmt: skip
    return out


def _flips(t: _Take, steps: tuple, spikes: tuple) -> list[Finding]:
    """Frames whose Euler angles are another triple of the same rotation than the frames before
    give: found by unrolling the joints whose angles jump by more than FLIP_DEG."""
    values = t.motion.values
    suspects: set[str] = set()
    for events, sizes in (steps, spikes):
        columns = events[:, 0]
        flipped = t.turning[columns] & (np.abs(sizes * t.degrees) > FLIP_DEG)
        suspects.update(t.channels[c].joint for c in columns[flipped].tolist())
    out = []
    for joint in sorted(suspects):
        if joint in t.triples:
            order, _, columns = t.triples[joint]
            angles = values[:, columns]
            rolled = unroll_euler(angles, order, degrees=t.degrees == 1.0)
        else:
            columns = t.columns(joint, True)
            angles = values[:, columns]
            rolled = np.unwrap(angles, axis=0, period=360.0 / t.degrees)
        delta = (rolled - angles) * t.degrees
        off = np.abs(delta).max(axis=1) > FLIP_DEG  # NaN compares false
        finite = np.isfinite(angles).all(axis=1)
        runs = _runs(off)
        # every frame but the first few off their triple: the first frames (a rest pose) are the flipped ones
        inverted = t.begins and t.ends and len(runs) == 1 and runs[0][0] <= LEAD_FRAMES and runs[0][1] == len(off) - 1
        if inverted:
            off = finite & ~off
        for first, last in _runs(off):
            beside = first - 1 if first > 0 else last + 1  # a frame of the other triple, for an inverted run
            shift = delta[beside] if inverted and beside < len(delta) else delta[first : last + 1]
            whole = bool(np.all(np.isclose(shift / 360, np.round(shift / 360), atol=1e-6)))
            edge = first if first > 0 else min(last + 1, len(angles) - 1)
            if joint in t.rotating and edge:
                q = t.quaternions(joint, np.array([edge - 1, edge]))
                if _angle_deg(q[0], q[1]) > FLIP_DEG / 2:
                    continue  # the rotation jumps too (a pop that unrolling changes): spikes and jumps judge it
            jump = float(np.nan_to_num(np.abs(angles[edge] - angles[edge - 1])).max()) * t.degrees if edge else 0.0
            fixable = not whole and first > 0
            what = "wrap by whole turns" if whole else "flip to the other Euler triple of the same rotation"
            lock = _lock_gap(t, joint, angles[max(first - 1, 0) : last + 2]) if not whole else None
            out.append(
                Finding(
                    t.name, "flip", (joint,), t.frame(first), t.frame(last), "low" if whole else "medium",
                    round(jump, 6), "deg",
                    f"{joint}'s Euler angles {what} for {last - first + 1} frame(s): a jump of {jump:.3g} deg "
                    "with no jump of the rotation"
                    + (f" (near gimbal lock: the middle angle comes within {lock:.2g} deg of it, where the first "
                       "and third swing fast)" if lock is not None else ""),
                    t.channels[int(columns[0])].name,
                    (("unroll", {"joints": [joint], "frames": [t.frame(first), t.frame(last)]}),) if fixable else (),
                )
            )  # fmt: skip
    return out


LOCK_DEG = 10.0
"""Degrees from gimbal lock within which a flip's middle angle tells the lock (the first and third
angles swing there, and the other triple is often the smoother)."""


def _lock_gap(t: _Take, joint: str, angles: np.ndarray) -> float | None:
    """How near the joint's Euler triple comes to gimbal lock over the rows ``angles`` (the middle
    angle's degrees from +-90 for Tait-Bryan orders, from 0 or 180 for proper Euler ones), where
    within LOCK_DEG; else None."""
    if joint not in t.triples:
        return None
    order = t.triples[joint][0]
    middle = np.radians(angles[:, 1] * t.degrees)
    off = np.abs(np.sin(middle) if order[0] == order[2] else np.cos(middle))  # 0 at the lock
    gap = float(np.degrees(np.arcsin(np.minimum(np.nanmin(off, initial=1.0), 1.0))))
    return gap if gap <= LOCK_DEG else None


def _runs(flags: np.ndarray) -> list[tuple[int, int]]:
    edges = np.diff(np.r_[0, flags.astype(np.int8), 0])
    return list(zip(np.flatnonzero(edges == 1).tolist(), (np.flatnonzero(edges == -1) - 1).tolist()))


def _pops(t: _Take, steps: tuple) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Jumps of a channel that a jump back within STEP_PAIR_SECONDS undoes, joined into
    excursions (channel, first, last, SPIKE, peak) with the first jump's size; and the jumps that
    stay.  Not of a joint's rotation channels: its rotation pairs its jumps (:func:`_excursions`)."""
    events, sizes = steps
    window = max(STEP_PAIR_SECONDS * t.rate, POP_FRAMES)
    pops, popsizes, kept = [], [], [True] * len(events)
    rows, values = events.tolist(), sizes.tolist()  # Python numbers: numpy's scalars cost more than the work
    for i in range(len(events) - 1):
        (c0, f0, *_), (c1, f1, *_) = rows[i], rows[i + 1]
        s0, s1 = values[i], values[i + 1]
        channel = t.channels[c0]
        if (
            not (channel.turns and channel.joint in t.rotating)
            and kept[i]
            and c0 == c1
            and 0 < f1 - f0 <= window
            and s0 * s1 < 0
            and abs(s0 + s1) < 0.5 * max(abs(s0), abs(s1))
        ):
            pops.append((c0, f0, f1 - 1, kernel.SPIKE, f0))
            popsizes.append(s0)
            kept[i] = kept[i + 1] = False
    table = np.array(pops, dtype=np.intp).reshape(-1, 5)
    return table, np.array(popsizes, dtype=float), np.array(kept, dtype=bool)


def _spikes(t: _Take, spikes: tuple, steps: tuple, explained: set, per_channel: np.ndarray) -> list[Finding]:
    events, sizes = spikes
    if not len(events) and not len(steps[0]):
        return []  # a clean take (21 of the 44 AMC takes here): the work below costs as much on none
    limits: list[float] = per_channel.tolist()  # Python floats: each candidate compares a few
    pops, popsizes, stay = _pops(t, steps)
    events, sizes = np.concatenate([events, pops]), np.concatenate([sizes, popsizes])
    values = t.motion.values
    rows = len(values)
    out = []
    edges: dict[int, list[tuple[str, float]]] = {}  # spikes at the first or last frame, by row
    candidates = [
        (joint, first, last, c, size)
        for joint, first, last, c, size in _joint_runs(t, events, sizes, pad=1)
        if not any((joint, t.channels[c].turns, t.frame(r)) in explained for r in range(first, last + 1))
    ]
    bounds = [t.physical(t.channels[c], limits[c]) for _, _, _, c, _ in candidates]
    trimmed = _trimmed(t, [(joint, t.channels[c].turns, a, b) for joint, a, b, c, _ in candidates], bounds)
    for (joint, _, _, c, size), limit, (first, last, deviation) in zip(candidates, bounds, trimmed):
        channel = t.channels[c]
        if deviation is None:  # at an end of the take, or beside a missing value
            deviation = abs(t.physical(channel, size))
            if channel.turns and (first == 0 or last == rows - 1):
                edges.setdefault(first, []).append((joint, deviation))
                continue
        if deviation <= limit:
            continue  # the angles swing (near gimbal lock) or the frames around move fast: no spike
        if channel.turns:
            out.append(_turning_spike(t, joint, channel.name, first, last, deviation, limit))
            continue
        speed = deviation * t.rate
        kind = "teleport" if joint == t.root and (speed > RUN_SPEED or deviation > TELEPORT_M) else "spike"
        severity = "high" if kind == "teleport" or deviation > 0.1 else "medium" if deviation > 0.03 else "low"
        out.append(
            Finding(
                t.name, kind, (joint,), t.frame(first), t.frame(last), severity, round(deviation, 6), "m",
                f"{joint} jumps {deviation:.3g} m away from its neighbours for {last - first + 1} frame(s)"
                + (f" and back: {speed:.3g} m/s, faster than anyone runs" if kind == "teleport" else ""),
                channel.name, _fill(t, first, last, [joint]),
            )
        )  # fmt: skip
    for row, turned in sorted(edges.items()):
        worst = max(d for _, d in turned)
        names = ", ".join(j for j, _ in turned[:4]) + (f" and {len(turned) - 4} more" if len(turned) > 4 else "")
        out.append(
            Finding(
                t.name, "spike", tuple(j for j, _ in turned), t.frame(row), t.frame(row), "low", round(worst, 6),
                "deg", f"frame {t.frame(row)} is another pose than the frames beside it (a rest pose?): {names} "
                f"{'turns' if len(turned) == 1 else 'turn'} up to {worst:.3g} deg away from them",
            )
        )  # fmt: skip
    # jumps that stay: of the root's position a teleport, of a rotation a jump (flips are found above)
    near_spike = np.zeros((len(t.channels), rows), bool)
    for c, first, last, *_ in events.tolist():
        near_spike[c, first : last + 1] = True
    events, sizes = steps
    seen, popped = set(), set()  # (joint, row): a joint's jump or pop shows in several of its channels
    jumps: list[tuple[str, int, float, int, bool]] = []  # (joint, row, degrees, channel, not a spike's)
    exact: list[Finding] = []  # the spikes the rotation's own jumps bound, in place of the candidates beside
    windows: list[Window] = []
    pops_seen: list[tuple[str, str, int, float]] = []  # (joint, channel, row, limit) of each pop
    for (c, first, last, _, at), size in zip(events[stay].tolist(), sizes[stay].tolist()):
        channel = t.channels[c]
        if channel.turns and channel.joint in t.rotating:
            # every row of a step: a turn-over's jumps out and back, a frame or two apart, make one
            # step of the angles with its peak at one of them
            limit = max(JUMP_DEG, limits[c] * t.degrees)
            span = range(max(first, 2), min(last, rows - 2) + 1)
            for row, (pop, jump) in zip(span, _rotation_steps(t, channel.joint, span, limit) if span else ()):
                if (channel.joint, row) in seen or (channel.joint, True, t.frame(row)) in explained:
                    continue
                seen.add((channel.joint, row))
                if pop is not None and (channel.joint, pop) not in popped:
                    popped.add((channel.joint, pop))
                    pops_seen.append((channel.joint, channel.name, pop, limit))
                elif pop is None and jump > limit:
                    jumps.append((channel.joint, row, jump, int(c), True))
            continue
        if (channel.joint, channel.turns, t.frame(at)) in explained or (
            channel.turns and abs(t.physical(channel, size)) > FLIP_DEG
        ):
            continue  # the unrolled angles tell a wrap by whole turns (above)
        # the jumps into and out of a spike are the spike's
        if near_spike[int(c), max(first - 1, 0) : last + 2].any():
            continue
        if channel.turns:
            if (channel.joint, at) not in seen:
                seen.add((channel.joint, at))
                jumps.append((channel.joint, at, abs(t.physical(channel, size)), int(c), True))
        elif channel.joint == t.root:
            distance = abs(t.physical(channel, size))
            out.append(
                Finding(
                    t.name, "teleport", (channel.joint,), t.frame(at), t.frame(at), "high", round(distance, 6), "m",
                    f"the root jumps {distance:.3g} m in one frame ({distance * t.rate:.3g} m/s) and stays there",
                    channel.name,
                )
            )  # fmt: skip
    offs = _deviations(t, [(joint, True, pop, pop) for joint, _, pop, _ in pops_seen])
    for (joint, name, pop, limit), off in zip(pops_seen, offs[:, 0].tolist()):
        if off > limit:  # NaN where it has none
            windows.append((joint, pop, pop + 1, math.inf, len(exact)))
            exact.append(_turning_spike(t, joint, name, pop, pop, off, limit))
    return _settled(t, _excursions(t, out, jumps, limits, exact, windows))


def _rotation_steps(t: _Take, joint: str, rows: range, limit: float) -> list[tuple[int | None, float]]:
    """What the joint's rotation does into each row (2 <= row <= rows - 2 of the take): the row of
    a pop (the rotation leaves for one frame and comes back, whatever its Euler angles do on the
    way out and back), found from the jump out or back, or None and the degrees it turns into
    the row more than the mean of its turns into the rows before and after."""
    # as Python floats: a step spans a row or a few, where numpy's scalars cost more than the work
    turn = t.turns(joint)[rows[0] - 2 : rows[-1] + 1].tolist()  # turn[k]: into row rows[0] - 1 + k
    back = t.turns(joint, 2)[rows[0] - 2 : rows[-1]].tolist()  # back[k]: from row rows[0] - 2 + k to two rows on
    out: list[tuple[int | None, float]] = []
    for i, row in enumerate(rows):
        pop = next(
            (
                row - 1 + side
                for side in (0, 1)
                if min(turn[i + side], turn[i + side + 1]) > limit
                and back[i + side] < 0.5 * min(turn[i + side], turn[i + side + 1])
            ),
            None,
        )
        out.append((pop, 0.0) if pop is not None else (None, turn[i + 1] - 0.5 * (turn[i] + turn[i + 2])))
    return out


def _excursions(
    t: _Take,
    out: list[Finding],
    jumps: list[tuple[str, int, float, int, bool]],
    limits: list[float],
    exact: list[Finding],
    windows: list[Window],
) -> list[Finding]:
    """The findings with the jumps added: a jump of a joint's rotation that a jump within
    FILL_SECONDS brings back to where it left (a thigh turned over for a third of a second, and
    the knee below it) is a spike of the frames between, fixed by filling them, in place of the
    spikes found within and beside them (as ``exact`` spikes, pops of one frame, are in place of
    those in their ``windows``); the others are jumps that stay, unless they lead into or out of
    a spike."""
    paired: set[tuple[str, int]] = set()
    pairs = _pairs(sorted(jumps), round(FILL_SECONDS * t.rate))
    # the pairs whose second jump brings the joint back
    pairs = [pair for pair, back in zip(pairs, _returns(t, pairs)) if back < 0.5 * min(pair[0][2], pair[1][2])]
    offs = _deviations(t, [(a[0], True, a[1], b[1] - 1) for a, b in pairs])
    for ((joint, a, _, c, _), (_, b, _, _, _)), off in zip(pairs, offs[:, 2].tolist()):
        if any(j == joint and a <= row <= b for j, row in paired):  # around an excursion paired already
            continue
        if math.isnan(off):
            continue
        paired.update({(joint, a), (joint, b)})
        windows.append((joint, a, b, math.inf, len(exact)))
        limit = t.physical(t.channels[c], limits[c])
        exact.append(_turning_spike(t, joint, t.channels[c].name, a, b - 1, off, limit))
    stay = [j for j in sorted(jumps) if (j[0], j[1]) not in paired and j[4]]
    turned = [jump > 30 and joint in t.rotating and 1 < at < t.motion.frames - 1 for joint, at, jump, _, _ in stay]
    seen_jumps = iter(t.seen_jumps([(j[0], j[1]) for j, turns in zip(stay, turned) if turns]))
    for (joint, at, jump, c, _), turns in zip(stay, turned):
        if joint in t.rotating:  # a rotation that jumps and stays: the spikes the median finds beside it are its
            windows.append((joint, at, at, jump, len(exact)))
        severity = "high" if jump > 90 else "medium" if jump > 30 else "low"
        seen, step, beside = next(seen_jumps) if turns else (math.inf, 0.0, 0.0)
        if seen < UNSEEN_M:  # a twist nothing drawn shows (a skinned mesh would), or fast motion
            severity = "medium" if severity == "high" else "low"
        elif severity == "high" and seen <= SEEN_M:
            severity = "medium"
        moved = f" (what it turns moves {step * 100:.2g} cm into that frame, {beside * 100:.2g} cm beside it)"
        moved = moved if turns else ""
        exact.append(
            Finding(
                t.name, "jump", (joint,), t.frame(at), t.frame(at), severity, round(jump, 6), "deg",
                f"{joint} turns {jump:.3g} deg more in one frame than in the frames beside it{moved}, and stays",
                t.channels[c].name,
            )
        )  # fmt: skip
    return _instead(t, out + exact, windows, len(out))


def _returns(t: _Take, pairs: list[tuple[tuple, tuple]]) -> list[float]:
    """For each pair of jumps (rows a and b) of a joint: how far, in degrees, its rotation at row
    b lies from where it was at row a - 1 or, over at most POP_FRAMES rows, from where its pace
    over rows a - 2 and a - 1 would have taken it (at 30 Hz a fast forearm turns 60 degrees over
    the three frames of a pop), whichever is nearer; every pair of a joint at once."""
    out = [math.inf] * len(pairs)
    for joint, members in _by_joint(joint for (joint, *_), _ in pairs).items():
        a = np.array([pairs[i][0][1] for i in members])
        b = np.array([pairs[i][1][1] for i in members])
        if joint not in t.rotating:
            for i, x, y in zip(members, a.tolist(), b.tolist()):
                out[i] = _apart(t, joint, x - 1, y)
            continue
        q = t.quaternions(joint, np.concatenate([a - 1, b, np.maximum(a - 2, 0)]))
        before, after, earlier = q[: len(a)], q[len(a) : 2 * len(a)], q[2 * len(a) :]
        back = _angle_deg(before, after)
        near = (b - a <= POP_FRAMES) & (a >= 2)
        if near.any():
            paced = slerp(earlier[near], before[near], (b - a + 2)[near].astype(float))
            back[near] = np.minimum(back[near], _angle_deg(after[near], paced))
        for i, value in zip(members, back.tolist()):
            out[i] = value
    return out


def _pairs(jumps: list[tuple[str, int, float, int, bool]], longest: int) -> list[tuple[tuple, tuple]]:
    """Each jump (sorted by joint and row) with each later jump of its joint more than one row and
    at most ``longest`` rows on, the pairs nearest together first: a jump back may come after
    others (a two-frame pop, whose middle frame jumps too), and an excursion within a longer
    stretch between two jumps is the excursion."""
    pairs = []
    for i, (joint, a, *_) in enumerate(jumps):
        for later in jumps[i + 1 :]:
            if later[0] != joint or later[1] - a > longest:
                break
            if later[1] - a > 1:
                pairs.append((jumps[i], later))
    return sorted(pairs, key=lambda pair: (pair[1][1] - pair[0][1], pair[0][0], pair[0][1]))


Window = tuple[str, int, int, float, int]
"""A joint, the row a rotation turns out at and the row it is back (the same row for a jump that
stays), the most degrees a spike there may turn to be of it, and how many findings were made
before it (those made after it are not of it)."""


def _instead(t: _Take, found: list[Finding], windows: list[Window], candidates: int) -> list[Finding]:
    """The findings without the spikes of a joint's rotation found within or beside a window made
    after them (of at most its degrees): the median of five around a frame beside a turn-over
    holds its frames, and the line between the frames around a stretch that holds one of its
    jumps leaves the frames between.  The first ``candidates`` findings were made before every
    window; each after them was made with the window of the same place in ``windows``."""
    by_joint: dict[str, list[tuple[int, int, float, int]]] = {}  # frames a spike beside it may reach
    for joint, first, back, below, after in windows:
        by_joint.setdefault(joint, []).append((t.frame(first) - 2, t.frame(back) + 1, below, after))

    def beside(f: Finding, made: int) -> bool:
        return any(
            after > made and f.size <= below and f.last >= low and f.first <= high
            for low, high, below, after in by_joint.get(f.joints[0], ())
        )

    return [
        f
        for made, f in enumerate(found)
        if not (f.kind == "spike" and len(f.joints) == 1 and f.unit == "deg" and beside(f, made - candidates))
    ]


def _apart(t: _Take, joint: str, first: int, last: int) -> float:
    """How far the joint's rotation at row ``last`` lies from row ``first``'s, in degrees (of a
    joint whose channels make no rotation, its angles' largest change, unwrapped)."""
    if joint in t.rotating:
        q = t.quaternions(joint, np.array([first, last]))
        return float(_angle_deg(q[0], q[1]))
    columns = t.columns(joint, True)
    block = _unwrapped(t.motion.values[first : last + 1, columns], t.motion.skeleton.period)
    return float(np.nan_to_num(np.abs(block[-1] - block[0]), nan=np.inf).max()) * t.degrees


def _turning_spike(
    t: _Take, joint: str, channel: str, first: int, last: int, deviation: float, limit: float
) -> Finding:
    """The spike of a joint's rotation over rows first..last, ``deviation`` degrees off the path
    between the rows around them (``limit`` the spike limit there)."""
    # high: farther out than smooth motion could go at six times the peak acceleration (30 deg
    # at 120 Hz; 67 deg at 30 Hz, where a fast wrist leaves its neighbours by 30), farther than the
    # joint turns per frame just before and after (a joint that turns as fast around it shakes:
    # a waving hand at 30 Hz), and in a turn no joint makes
    high = deviation > max(30, 6 * limit)
    if high:
        pace, fastest = _paces(t, joint, first, last)
        high = deviation > 2 * pace and fastest > SPIKE_TURN_DEG_S
    # medium: farther out than smooth motion at twice the peak acceleration (10 deg at 45 Hz and
    # above; 22 at 30 Hz, where a swinging forearm bends off the path between its neighbours by
    # 15), or farther out than the rows around it lie apart: a turn out and back
    medium = deviation > 10 and (
        deviation > 2 * limit
        or (first > 0 and last < t.motion.frames - 1 and deviation > _apart(t, joint, first - 1, last + 1))
    )
    finding = Finding(
        t.name, "spike", (joint,), t.frame(first), t.frame(last), "low", round(deviation, 6), "deg",
        f"{joint} turns {deviation:.3g} deg away from its neighbours for {last - first + 1} frame(s)",
        channel, _fill(t, first, last, [joint]),
    )  # fmt: skip
    if high or medium:  # what it moves settles it (low, whatever it moves, otherwise)
        t.unsettled[id(finding)] = (finding, first, last, deviation, high)
    return finding


def _settled(t: _Take, found: list[Finding]) -> list[Finding]:
    """The findings with each turning spike that its angles make medium or high settled by what it
    moves (:meth:`_Take.seen`, for all of them at once): high only where what it turns leaves its
    path by more than SEEN_M; at most medium where it moves nothing drawn; told and not filled
    where the take looks right and filling the joint alone would not."""
    todo = [(i, t.unsettled[id(f)]) for i, f in enumerate(found) if id(f) in t.unsettled]
    seen = t.seen([(f.joints[0], first, last) for _, (f, first, last, _, _) in todo])
    out = list(found)
    for (i, (f, first, last, deviation, high)), (off, filled) in zip(todo, seen):
        nearest = min(off, filled)
        # the take looks right, or nearly (the joints below turn it back, or it is the path the
        # motion takes), and filling this joint alone would put out what it turns four times as
        # far: told, not filled; medium where the angles are turned over (wrong for anyone who
        # edits or retargets them), else low
        undone = off <= 2 * SEEN_M and filled > 4 * off + SEEN_M
        severity = (
            ("medium" if high else "low") if nearest < UNSEEN_M  # a twist nothing drawn shows: for a skinned mesh
            else ("medium" if deviation > FLIP_DEG else "low") if undone
            else "high" if high and nearest > SEEN_M
            else "medium"
        )  # fmt: skip
        what = (
            f"but what it turns stays within {off * 100:.2g} cm of its path (the joints below turn it back, or the "
            f"motion goes so): told, not filled, which would move them {filled * 100:.2g} cm"
            if undone
            else f"moving what it turns {nearest * 100:.2g} cm off its path"
        )
        out[i] = Finding(
            f.take, f.kind, f.joints, f.first, f.last, severity, f.size, f.unit, f"{f.detail}, {what}", f.channel,
            () if undone else f.fix,
        )  # fmt: skip
    t.unsettled.clear()
    return out


Run = tuple[str, bool, int, int]
"""A joint's rotation (True) or position (False) over rows first..last: (joint, turns, first, last)."""


def _deviations(t: _Take, runs: list[Run]) -> np.ndarray:
    """For each run, how far its rows lie off the path between the rows around it: the joint's
    rotation in degrees from the SLERP between them (its angles, unwrapped, from the line
    between them where it has fewer than three), or its position in metres from the line
    between them.  (runs, 3): the first row's, the last row's and the largest; NaN at an end of
    the take or where a value is missing.  Every run at once: a take's candidates are many, and
    each alone costs a dozen numpy calls."""
    out = np.full((len(runs), 3), np.nan)
    groups: dict[tuple[bool, int], list[int]] = {}  # (turns, columns; 0 for a joint's rotation): runs
    for i, (joint, turns, first, last) in enumerate(runs):
        if first >= 1 and last <= t.motion.frames - 2:
            key = (True, 0) if turns and joint in t.rotating else (turns, len(t.columns(joint, turns)))
            groups.setdefault(key, []).append(i)
    for (turns, columns), members in groups.items():
        chosen = [runs[i] for i in members]
        out[members] = _line_deviations(t, chosen, turns) if columns else _slerp_deviations(t, chosen)
    return out


def _blocks(runs: list[Run]) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The rows of each run with the row before and after it, end to end: those rows, where each
    run's block starts (and, last, where they all end), the inner rows' places among them, and
    the inner rows' shares of the way from the row before their run to the row after it."""
    first = np.array([first for _, _, first, _ in runs])
    sizes = np.array([last for _, _, _, last in runs]) - first + 3
    starts = np.concatenate(([0], np.cumsum(sizes)))
    place = np.arange(starts[-1]) - np.repeat(starts[:-1], sizes)  # 0 .. size - 1 in each block
    across = np.repeat(sizes - 1, sizes)
    inner = np.flatnonzero((place > 0) & (place < across))
    return np.repeat(first - 1, sizes) + place, starts, inner, place[inner] / across[inner]


def _summed(off: np.ndarray, starts: np.ndarray, missing: np.ndarray) -> np.ndarray:
    """The inner rows' deviations (each block without its two outer rows) run by run: the first
    row's, the last row's and the largest, NaN where a run misses a value."""
    sizes = np.diff(starts) - 2
    ends = np.cumsum(sizes)
    begins = ends - sizes
    out = np.stack([off[begins], off[ends - 1], np.maximum.reduceat(off, begins)], axis=1)
    out[missing] = np.nan
    return out


def _slerp_deviations(t: _Take, runs: list[Run]) -> np.ndarray:
    rows, starts, inner, share = _blocks(runs)
    sizes = np.diff(starts)
    joints = list({joint: None for joint, *_ in runs})
    owners = np.repeat([joints.index(joint) for joint, *_ in runs], sizes)
    q = np.empty((len(rows), 4))
    for k, joint in enumerate(joints):
        mine = owners == k
        q[mine] = t.quaternions(joint, rows[mine])
    # a missing angle makes its quaternion NaN (no quaternion is infinite)
    missing = np.add.reduceat(np.isnan(q[:, 0] + q[:, 1] + q[:, 2] + q[:, 3]), starts[:-1]) > 0
    before, after = np.repeat(starts[:-1], sizes)[inner], np.repeat(starts[1:] - 1, sizes)[inner]
    between = slerp(q[before], q[after], share)
    return _summed(_angle_deg(q[inner], between), starts, missing)


def _line_deviations(t: _Take, runs: list[Run], turns: bool) -> np.ndarray:
    rows, starts, inner, share = _blocks(runs)
    sizes = np.diff(starts)
    columns = np.repeat(np.array([t.columns(joint, turns) for joint, *_ in runs]), sizes, axis=0)
    block = t.motion.values[rows[:, None], columns]
    missing = np.add.reduceat(np.isnan(block).any(axis=1), starts[:-1]) > 0
    if turns:
        period = t.motion.skeleton.period
        wraps = np.abs(np.diff(block, axis=0)) >= period / 2  # numpy's unwrap changes nothing below
        wraps[starts[1:-1] - 1] = False  # a step from one run's block to the next is none
        for k in np.flatnonzero(np.add.reduceat(wraps.any(axis=1), starts[:-1]) > 0):
            block[starts[k] : starts[k + 1]] = np.unwrap(block[starts[k] : starts[k + 1]], axis=0, period=period)
    block = block * (t.degrees if turns else t.meters)
    before, after = np.repeat(starts[:-1], sizes)[inner], np.repeat(starts[1:] - 1, sizes)[inner]
    line = block[before] + share[:, None] * (block[after] - block[before])
    off = block[inner] - line
    return _summed(np.abs(off).max(axis=1) if turns else lengths(off), starts, missing)


def _unwrapped(block: np.ndarray, period: float) -> np.ndarray:
    """The block's columns unwrapped along its rows (numpy's unwrap), skipped where no step
    between rows reaches half a turn: there unwrapping changes nothing, and nearly every block of
    a candidate is so."""
    if (np.abs(np.diff(block, axis=0)) < period / 2).all():
        return block
    return np.unwrap(block, axis=0, period=period)


PACE_FRAMES = 3


def _paces(t: _Take, joint: str, first: int, last: int) -> tuple[float, float]:
    """How fast the joint turns around rows first..last (first >= 1) and through them: the most
    it turns from one frame to the next over the PACE_FRAMES frames before them and after them,
    in degrees (0 where its channels make no rotation), and the fastest it turns from one frame
    to the next from the row before them to the row after, in degrees per second (inf where its
    channels make no rotation, where the check has no other measure than the channel's own).
    NaN steps (a gap) are left out."""
    if joint not in t.rotating:
        return 0.0, math.inf
    low, steps_end = max(first - PACE_FRAMES, 0), t.motion.frames - 1
    # entry k: from row low + k to the next; a few steps, where Python's floats cost less than numpy's calls
    steps = t.turns(joint)[low : min(last + PACE_FRAMES, steps_end)].tolist()

    def most(a: int, b: int) -> float:  # of the steps from rows a .. b - 1
        return max(
            (x for x in steps[max(a, 0) - low : max(min(b, steps_end) - low, 0)] if not math.isnan(x)), default=0.0
        )

    pace = max(most(first - PACE_FRAMES, first - 1), most(last + 1, last + PACE_FRAMES))
    return pace, most(first - 1, last + 1) * t.rate


def _trimmed(t: _Take, runs: list[Run], limits: list[float]) -> list[tuple[int, int, float | None]]:
    """Each run without the rows at its ends that lie on the path between the rows around them
    (the median of five beside a large spike can leave a fast-moving neighbour), and its largest
    deviation (None where :func:`_deviations` has none): (first, last, deviation).  A joint's
    rotation is trimmed in C (:func:`mtcore.check.trim_runs`); positions, and angles that make
    no rotation, here, every run at once, a row at a time, while any still loses one."""
    first = np.array([first for _, _, first, _ in runs], dtype=np.intp)
    last = np.array([last for _, _, _, last in runs], dtype=np.intp)
    limit = np.asarray(limits, dtype=float)
    largest = np.full(len(runs), np.nan)
    turning = np.array([turns and joint in t.rotating for joint, turns, _, _ in runs], dtype=bool)
    rotations = np.flatnonzero(turning)
    for joint, members in _by_joint(runs[i][0] for i in rotations.tolist()).items():
        mine = rotations[members]
        trimmed = kernel.trim_runs(t.quaternions(joint, slice(None)), first[mine], last[mine], limit[mine])
        first[mine], last[mine], largest[mine] = trimmed
    pending = np.flatnonzero(~turning)  # the others' positions or angles, a row at a time here
    while len(pending):
        off = _deviations(t, [(*runs[i][:2], a, b) for i, a, b in zip(pending, first[pending], last[pending])])
        head = off[:, 0] <= limit[pending]  # NaN: no deviations, nothing trimmed
        trims = (first[pending] < last[pending]) & (head | (off[:, 1] <= limit[pending]))
        largest[pending[~trims]] = off[~trims, 2]
        pending = pending[trims]
        first[pending] += head[trims]
        last[pending] -= ~head[trims]
    return [(a, b, None if math.isnan(d) else d) for a, b, d in zip(first.tolist(), last.tolist(), largest.tolist())]


def _jitter(t: _Take, roughness: np.ndarray, counts: np.ndarray) -> list[Finding]:
    smooth = SMOOTH_ACCELERATION_DEG * t.dt**2 / 2
    with np.errstate(invalid="ignore", divide="ignore"):
        noise = np.sqrt(roughness / counts / 1.5)
    levels = noise * np.where(t.turning, t.degrees, t.meters)
    limits = np.where(t.turning, max(JITTER_DEG, smooth), JITTER_M)
    worst: dict[str, tuple[float, int]] = {}
    for c in np.flatnonzero(levels > limits).tolist():
        ratio = float(levels[c]) / float(limits[c])
        if ratio > worst.get(t.channels[c].joint, (0.0, 0))[0]:
            worst[t.channels[c].joint] = (ratio, c)
    out = []
    for joint, (ratio, c) in sorted(worst.items()):
        channel = t.channels[c]
        level = t.physical(channel, float(noise[c]))
        severity = "medium" if ratio > 2 else "low"
        out.append(
            Finding(
                t.name, "jitter", (joint,), t.motion.first_frame, t.motion.last_frame, severity, round(level, 6),
                t.unit(channel), f"{channel.name} jitters by about {level:.3g} {t.unit(channel)} frame to frame",
                channel.name,
                # a low pass needs every value: a joint with a gap left unfilled gets none
                (("butterworth", {"joints": [joint]}),) if severity == "medium" and not t.gaps(joint) else (),
            )
        )  # fmt: skip
    return out


def _bones(t: _Take) -> list[Finding]:
    out = []
    skeleton = t.motion.skeleton
    above = set(_chain_to(skeleton, t.root))  # the body's joint and those above it carry no bone
    placed = skeleton.derived("check bones", lambda: _placed_joints(t.motion))
    for joint, columns in placed:
        if joint in above:
            continue
        length = lengths(t.motion.values[:, columns]) * t.meters
        if not np.isfinite(length).any():
            continue
        middle = float(np.nanmedian(length))
        off = np.abs(length - middle)
        bad = off > max(BONE_DRIFT_M, BONE_DRIFT_SHARE * middle)  # NaN compares false
        for first, last in _runs(bad):
            size = float(np.nanmax(off[first : last + 1]))
            out.append(
                Finding(
                    t.name, "bone", (joint,), t.frame(first), t.frame(last), "medium", round(size, 6), "m",
                    f"the bone to {joint} is {size:.3g} m off its usual {middle:.3g} m",
                    f"{joint} tx",
                )
            )  # fmt: skip
    return out


def _placed_joints(motion: Motion) -> list[tuple[str, list[int]]]:
    """The joints with three position channels, and their columns."""
    skeleton = motion.skeleton
    return [
        (joint, motion.columns(joint, TRANSLATIONS))
        for joint in skeleton.joint_names
        if set(TRANSLATIONS) <= set(skeleton.dofs(joint)) and len(motion.columns(joint, TRANSLATIONS)) == 3
    ]


def _chain_to(skeleton, joint: str) -> list[str]:
    chain = [joint]
    while not skeleton.is_root(chain[-1]):
        chain.append(skeleton.parent(chain[-1]))
    return chain


def _speed(t: _Take) -> list[Finding]:
    columns = t.motion.columns(t.root, TRANSLATIONS) if t.motion.frames > 1 else []
    if len(columns) != 3:
        return []
    window = max(1, round(0.25 * t.rate))
    steps = lengths(np.diff(t.motion.values[:, columns], axis=0)) * t.meters * t.rate
    if not np.fmax.reduce(steps, initial=0.0) > RUN_SPEED:  # no median of them can be: the take is slower
        return []
    # the median over 0.25 s: a teleport of a few frames is not a speed
    typical = median_filter1d(np.where(np.isnan(steps), 0.0, steps), window | 1, mode="nearest")
    out = []
    for first, last in _runs(typical > RUN_SPEED):
        speed = float(typical[first : last + 1].max())
        out.append(
            Finding(
                t.name, "speed", (t.root,), t.frame(first), t.frame(last + 1), "high", round(speed, 6), "m/s",
                f"the root moves at {speed:.3g} m/s for 0.25 s or more, faster than anyone runs: "
                "is the length unit or the frame rate wrong?",
                f"{t.root} tx",
            )
        )  # fmt: skip
    return out


UNIT_FACTORS = (10.0, 0.1, 100.0, 0.01, 1000.0, 0.001, 2.54, 1 / 2.54, 25.4, 1 / 25.4)
"""The factors a length unit is usually off by (a named unit for another)."""
HUMAN_JOINTS = 10
"""A skeleton with fewer joints may be no person: its size tells nothing wrong with its unit."""
TYPICAL_HEIGHT_M = 1.75
"""Metres: of the factors that make the character human-sized, the recipe takes the one that
makes it nearest this."""


def _unit(t: _Take) -> list[Finding]:
    sizing = t.motion.skeleton.sizing()
    height = sizing.told_by * t.meters
    if HUMAN_HEIGHT[0] <= height < HUMAN_HEIGHT[1] or height == 0 or len(t.motion.skeleton.joint_names) < HUMAN_JOINTS:
        return []  # a person's size, or no person (a chain of a few bones) whose size could tell
    fits = [f for f in UNIT_FACTORS if HUMAN_HEIGHT[0] <= height * f < HUMAN_HEIGHT[1]]
    fits.sort(key=lambda f: abs(math.log(height * f / TYPICAL_HEIGHT_M)))  # the likeliest first
    unit = t.motion.skeleton.length_unit or "inch"
    return [
        Finding(
            t.name, "unit", (), t.motion.first_frame, t.motion.last_frame, "high", round(height, 6), "m",
            f"the character is {height:.3g} m {'tall' if sizing.axis in (None, sizing.up) else 'wide'} "
            f"in the length unit in effect ({unit}, {t.motion.skeleton.length_source})"
            + (f": lengths {fits[0]:g} times as long make it {height * fits[0]:.3g} m" if fits else ""),
            fix=(("scale", {"factor": fits[0]}),) if fits else (),
        )
    ]  # fmt: skip


def header_finding(motion: Motion, cut: Cut, take: str = "") -> Finding:
    """The finding of a take whose file disagrees with its header (``cut``, as
    :func:`~motiontheater.formats.table.read_take_frames` found it; ``motion`` its whole frames),
    fixed by reading the whole frames and writing them anew (a recipe's whole_frames)."""
    declared = motion.frames + 1 if cut.declared is None else cut.declared
    first, last = sorted(
        (motion.first_frame + min(declared, cut.held), motion.first_frame + max(declared, cut.held) - 1)
    )
    seconds = (last - first + 1) / motion.frame_rate
    return Finding(
        take, "header", (), first, last, "high", round(seconds, 6), "s",
        f"{cut.reason} (line {cut.line}); the rest is checked on the {motion.frames} whole frames",
        fix=(("whole_frames", {}),),
    )  # fmt: skip


def recipe(findings: Iterable[Finding], severities: tuple[str, ...] = ("medium", "high")) -> Pipeline:
    """The steps that fix the findings of ``severities`` (those with a fix): unit first, then
    flips, then the frames filled, then smoothing, then the feet, each confined to its frames and
    joints; a file that breaks off read for its whole frames."""
    order = ("scale", "unroll", "fill_gaps", "butterworth", "cleanup")
    entries = [step for f in findings if f.severity in severities for step in f.fix]
    whole = any(name == "whole_frames" for name, _ in entries)
    entries = [e for e in entries if e[0] != "whole_frames"]
    entries.sort(key=lambda e: order.index(e[0]) if e[0] in order else len(order))
    pipeline = Pipeline(whole_frames=whole)
    seen = []
    for name, options in entries:
        if (name, options) in seen:
            continue
        seen.append((name, options))
        pipeline = pipeline.then(name, **options)
    return pipeline
