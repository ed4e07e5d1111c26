"""Signal processing of whole motions: frequency bands, Butterworth filtering, resampling, gap filling.

Four steps (each a method, a command-line verb, a Pipeline step and a batch
step through the registry), and the analyses behind them:

- ``equalize`` (verb ``bands`` too): the motion signal processing of
  Bruderlin and Williams (SIGGRAPH 1995), each frequency band scaled by a gain;
- ``butterworth``: a zero-lag low-, high- or band-pass, cut-off in Hz, or
  chosen by Winter's residual analysis (:func:`residual_analysis`, and the
  ``residuals`` exporter, which writes it per channel);
- ``resample``: any new frame rate, translations through an anti-aliasing
  polyphase filter, rotations as rotations (unit quaternions);
- ``fill_gaps``: short runs of missing values filled (linearly, by cubic
  spline, or rotations by SLERP), longer ones listed (:func:`find_gaps`).

Rotation channels are handled as the smoothing filters handle them: angles
are unwrapped (whole turns added where a channel jumps by more than half a
turn), filtered, and wrapped back into the range the channel used;
resampling and SLERP go through quaternions instead.  The numeric work is
:mod:`mtcore.signal` and :mod:`mtcore.rotations`, in C.  Frequencies are in
Hz and durations in seconds, from the motion's frame rate.

What a step finds worth knowing (the cut-off Winter's analysis chose, gaps
left unfilled) goes to the ``motiontheater`` logger, which the command line
prints.
"""

from __future__ import annotations

import csv
import io
import logging
import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Annotated, Literal, NamedTuple

import numpy as np

from mtcore import rotations as rot
from mtcore import signal as sg
from mtcore.text import format_number

from .._io import Source, output
from ..model.motion import Motion
from ..model.registry import Frames, Joints, exporter, step
from ..model.skeleton import ROTATIONS
from .filtering import EdgeMode, TakeStats, _wrap_into, unwrap_angles

log = logging.getLogger("motiontheater")

Workers = Annotated[int | None, "threads (default: every core for large takes)"]


# ---------------------------------------------------------------------------
# channels: which columns, unwrapped and wrapped back


def _columns(motion: Motion, joints: Iterable[str] | None, translation: bool = True) -> tuple[list[int], list[int]]:
    """(rotation columns, other columns) of the chosen joints (all by default); the others
    (translations, stretch) only with ``translation``."""
    rotations: list[int] = []
    others: list[int] = []
    skeleton = motion.skeleton
    for joint in skeleton.joint_names if joints is None else tuple(joints):
        for column, dof in zip(motion.columns(joint), skeleton.dofs(joint)):
            if dof in ROTATIONS:
                rotations.append(column)
            elif translation:
                others.append(column)
    return rotations, others


def _unwrapped(angles: np.ndarray, period: float) -> np.ndarray:
    """Angle columns unwrapped as the smoothing filters unwrap them (NaN stepped over and kept)."""
    return unwrap_angles(angles, period)[0] if len(angles) else angles.copy()


def _ranges(angles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each column's range of finite values, which the wrap-back keeps it in."""
    stats = TakeStats.of(angles)
    return stats.low, stats.high


def _filtered(
    motion: Motion, rotations: list[int], others: list[int], apply: Callable[[np.ndarray], np.ndarray]
) -> np.ndarray:
    """A copy of the values with ``apply`` run on the chosen columns, (frames, columns) in and out:
    rotations unwrapped before and wrapped back into their range after; every column relative to
    its first frame, so that a constant channel stays exactly constant."""
    values = motion.values.copy()
    period = motion.skeleton.period
    for columns, turning in ((rotations, True), (others, False)):
        if not columns:
            continue
        block = motion.values[:, columns]
        unwrapped = _unwrapped(block, period) if turning else block
        base = unwrapped[0]
        result = apply(unwrapped - base) + base
        values[:, columns] = _wrap_into(result, *_ranges(block), period) if turning else result
    values.flags.writeable = False
    return values


# ---------------------------------------------------------------------------
# the band equaliser


@step(
    "equalize",
    "scale the motion's frequency bands, finest first (the Bruderlin-Williams equaliser)",
    aliases=("bands",),
)
def equalize(
    motion: Motion,
    *,
    gains: Annotated[tuple[float, ...], "gain of each band, finest first (later bands keep 1)"],
    joints: Annotated[Joints, "joints to equalise (default: all)"] = None,
    translation: Annotated[bool, "equalise the root's translation too"] = True,
    mode: Annotated[EdgeMode, "how each level is extended past the ends: nearest holds the end values"] = "nearest",
    workers: Workers = None,
) -> Motion:
    """A new motion whose frequency bands are scaled by the gains (Bruderlin and Williams 1995).

    The frames are split into bands by a pyramid of the binomial kernel
    (1 4 6 4 1) / 16 whose taps are 2^k frames apart at level k (no level is
    decimated): band k is level k minus level k + 1, and a take of N frames
    has floor(log2 N) of them.  At 120 Hz band 0 holds about 22-60 Hz (jitter),
    band 1 11-22 Hz, band 2 5.5-11 Hz, each next band an octave lower.  The
    result is the coarsest level plus each band times its gain: gains above 1
    exaggerate a band, below 1 damp it, 0 removes it; all gains 1 give the
    motion back exactly.  The levels are extended past the ends by the mode
    (nearest: the end values held, as a take that starts and ends at rest).
    Rotation channels are unwrapped first and wrapped back after; the other
    joints' channels stay bit-identical.  NaN spreads: fill gaps first.
    """
    rotations, others = _columns(motion, joints, translation)
    bands = sg.band_count(motion.frames)
    if len(gains) > bands:
        raise ValueError(
            f"gains: {len(gains)} gains given, but a take of {motion.frames} frames has only {bands} bands "
            f"(floor(log2 {motion.frames}))"
        )
    if not motion.frames or all(g == 1 for g in gains):  # every band as it is: the motion itself, exactly
        return motion.replace(values=motion.values)
    values = _filtered(motion, rotations, others, lambda x: sg.equalize(x, gains, axis=0, mode=mode, workers=workers))
    return motion.replace(values=values)


# ---------------------------------------------------------------------------
# Butterworth and Winter's residual analysis


@dataclass(frozen=True)
class ResidualReport:
    """Winter's residual analysis of a motion's channels (see :func:`residual_analysis`).

    ``channels``: (joint, dof) of each channel analysed; ``cutoffs`` (Hz) and
    ``noise`` (the RMS noise estimate, in the channel's unit) per channel, NaN
    where the analysis finds none (a constant channel); ``frequencies`` (Hz)
    the cut-offs tried and ``residuals`` (frequencies, channels) the RMS
    residual at each.
    """

    channels: tuple[tuple[str, str], ...]
    cutoffs: np.ndarray
    noise: np.ndarray
    frequencies: np.ndarray
    residuals: np.ndarray

    @property
    def cutoff(self) -> float:
        """The motion's cut-off (Hz): the median of the channels' (NaN if none has one)."""
        found = self.cutoffs[np.isfinite(self.cutoffs)]
        return float(np.median(found)) if len(found) else math.nan


def residual_analysis(
    motion: Motion,
    joints: Iterable[str] | None = None,
    *,
    translation: bool = True,
    order: int = 2,
    workers: int | None = None,
) -> ResidualReport:
    """Winter's residual analysis of each chosen channel (rotations unwrapped): the cut-off
    where the residual of a zero-lag Butterworth of ``order`` falls to the noise level (see
    :func:`mtcore.signal.residual_cutoff`).  Needs more than 9 frames."""
    rotations, others = _columns(motion, joints, translation)
    columns = rotations + others
    if motion.frames <= 9:
        raise ValueError(f"Winter's residual analysis needs more than 9 frames; the motion has {motion.frames}")
    block = motion.values[:, columns].copy()
    block[:, : len(rotations)] = _unwrapped(block[:, : len(rotations)], motion.skeleton.period)
    analysis = sg.residual_cutoff(block - block[0], motion.frame_rate, axis=0, order=order, workers=workers)
    return ResidualReport(
        channels=tuple(motion.channels[c] for c in columns),
        cutoffs=analysis.cutoff,
        noise=analysis.intercept,
        frequencies=analysis.frequencies,
        residuals=analysis.residuals,
    )


@exporter("residuals", (".csv",), "write Winter's residual analysis: the cut-off each channel suggests (Hz)")
def write_residuals(
    motion: Motion,
    target: Source,
    *,
    joints: Annotated[Joints, "joints to analyse (default: all)"] = None,
    translation: Annotated[bool, "analyse the root's translation too"] = True,
) -> None:
    """Write Winter's residual analysis of each channel as CSV: joint, dof, cutoff_hz (where the
    residual falls to the noise level, empty for a constant channel) and noise (the RMS noise
    estimate in the channel's unit), then a last row "motion", "", the median cut-off."""
    report = residual_analysis(motion, joints, translation=translation)
    text = io.StringIO()
    writer = csv.writer(text, lineterminator="\n")
    writer.writerow(["joint", "dof", "cutoff_hz", "noise"])

    def number(x: float) -> str:
        return "" if math.isnan(x) else format_number(round(float(x), 6))

    for (joint, dof), cutoff, noise in zip(report.channels, report.cutoffs, report.noise):
        writer.writerow([joint, dof, number(cutoff), number(noise)])
    writer.writerow(["motion", "", number(report.cutoff), ""])
    with output(target) as f:
        f.write(text.getvalue().encode())


@step("butterworth", "zero-lag Butterworth filter (low, high or band pass), cut-off in Hz")
def butterworth(
    motion: Motion,
    *,
    cutoff: Annotated[
        tuple[float, ...] | None, "cut-off in Hz (two for band: LOW,HIGH); default: Winter's residual analysis"
    ] = None,
    order: Annotated[int, "filter order (1-8 are usual); run forward and backward, so it cuts twice as steeply"] = 4,
    kind: Annotated[Literal["low", "high", "band"], "pass band"] = "low",
    joints: Annotated[Joints, "joints to filter (default: all)"] = None,
    translation: Annotated[bool, "filter the root's translation too"] = True,
    workers: Workers = None,
) -> Motion:
    """A new motion filtered by a Butterworth filter forward and backward (no lag).

    As ``scipy.signal.sosfiltfilt(scipy.signal.butter(order, cutoff, kind,
    fs=frame_rate, output="sos"), ...)``, bit for bit, along the frames: the
    response at the cut-off is half the input (-6 dB: -3 dB each way), the
    ends extended by point reflection (3 (order + 1) frames or so, which the
    take must exceed).  Without a cut-off, Winter's residual analysis chooses
    one for a low pass (the median of the channels'; logged) - see the
    ``residuals`` exporter for each channel's.  Rotation channels are
    unwrapped first and wrapped back after; the other joints' channels stay
    bit-identical, and a constant channel stays exactly constant.  NaN
    spreads over its channel: fill gaps first.
    """
    if isinstance(order, bool) or order < 1:
        raise ValueError(f"order must be a positive whole number, got {order!r}")
    if isinstance(cutoff, (int, float)):  # a plain call may give one frequency as a number
        cutoff = (float(cutoff),)
    rotations, others = _columns(motion, joints, translation)
    nyquist = motion.frame_rate / 2
    if cutoff is None:
        if kind != "low":
            raise ValueError(f"cutoff: give the cut-off of a {kind} pass (Winter's analysis chooses low passes only)")
        report = residual_analysis(motion, joints, translation=translation, workers=workers)
        if math.isnan(report.cutoff):
            raise ValueError("cutoff: Winter's residual analysis found no noise to cut (constant channels); give one")
        cutoff = (report.cutoff,)
        log.info("butterworth: Winter's residual analysis chose a cut-off of %.3g Hz", report.cutoff)
    needed = 2 if kind == "band" else 1
    if len(cutoff) != needed:
        raise ValueError(f"cutoff: a {kind} pass takes {needed} frequencies (Hz), got {len(cutoff)}")
    for f in cutoff:
        if not 0 < f < nyquist:
            raise ValueError(
                f"cutoff: {f:g} Hz is not between 0 and the Nyquist frequency {nyquist:g} Hz (half the frame rate)"
            )
    if kind == "band" and not cutoff[0] < cutoff[1]:
        raise ValueError(f"cutoff: the band's low cut-off {cutoff[0]:g} Hz must be below its high one {cutoff[1]:g} Hz")
    sos = sg.butter_sos(order, cutoff if kind == "band" else cutoff[0], kind, fs=motion.frame_rate)
    padlen = 3 * (2 * len(sos) + 1 - min(int((sos[:, 2] == 0).sum()), int((sos[:, 5] == 0).sum())))
    if motion.frames <= padlen:
        raise ValueError(
            f"a Butterworth of order {order} ({kind} pass) needs more than {padlen} frames; "
            f"the motion has {motion.frames}"
        )
    values = _filtered(motion, rotations, others, lambda x: sg.sosfiltfilt(sos, x, axis=0, workers=workers))
    return motion.replace(values=values)


# ---------------------------------------------------------------------------
# resampling


def _resampled_lines(x: np.ndarray, up: int, down: int, workers: int | None) -> np.ndarray:
    """Columns of x (frames, k) at up / down times the rate: the straight line through the
    first and last frames is taken out (and put back at the new frames), so that constants
    and straight lines come out exact; the rest is filtered by resample_poly, its ends
    extended by point reflection (slopes continue, nothing rings)."""
    n = len(x)
    n_out = (n - 1) * up // down + 1  # frames from the first to the last frame's time, no later
    if n < 2:
        return np.repeat(x, n_out, axis=0)
    slope = (x[-1] - x[0]) / (n - 1)
    line_in = x[0] + np.arange(n)[:, None] * slope
    line_out = x[0] + (np.arange(n_out) * down / up)[:, None] * slope
    rest = sg.resample_poly(x - line_in, up, down, axis=0, padtype="antireflect", workers=workers)
    return rest[:n_out] + line_out


def _steady_near_gimbal_lock(
    path: np.ndarray,
    angles: np.ndarray,
    q_out: np.ndarray,
    convention: tuple[str, bool, bool],
    up: int,
    down: int,
    workers: int | None,
) -> None:
    """Near gimbal lock (the middle angle near +-90 degrees, or 0 and 180) a rotation's Euler angles
    turn on a hair: the first and last angles of a rotation a fraction of a degree away can differ
    by tens of degrees.  Where the angles from the resampled quaternions (``path``, frames x joints
    x 3) leave the channels resampled one by one by more than 5 degrees while both give the same
    rotation to within 0.5 degrees, the channels' own are kept (in place), so that no channel jumps."""
    order, extrinsic, degrees = convention
    n = len(angles)
    direct = _resampled_lines(_unwrapped(angles.reshape(n, -1), 360.0 if degrees else 2 * math.pi), up, down, workers)
    direct = direct.reshape(path.shape)
    half = 180.0 if degrees else math.pi
    apart = np.abs((path - direct + half) % (2 * half) - half).max(axis=-1)
    if not np.any(apart > (5.0 if degrees else math.radians(5.0))):
        return
    q_direct = rot.euler_to_quaternions(direct, order, extrinsic=extrinsic, degrees=degrees)
    turn = np.degrees(2 * np.arccos(np.clip(np.abs(np.sum(q_direct * q_out, axis=-1)), 0.0, 1.0)))
    keep = (apart > (5.0 if degrees else math.radians(5.0))) & (turn < 0.5)
    path[keep] = direct[keep]


@step("resample", "change the frame rate (e.g. 120 to 30 Hz): anti-aliased, rotations as rotations", frames="none")
def resample(
    motion: Motion,
    *,
    rate: Annotated[float, "frames per second of the result"],
    rotations: Annotated[
        Literal["filter", "slerp"], "rotations to a higher rate: filter the quaternions, or SLERP between frames"
    ] = "filter",
    workers: Workers = None,
) -> Motion:
    """A new motion at another frame rate, over the same time span.

    The rate ratio is taken exactly from the rates as written (119.875 to
    120 is 960/959), and frame j of the result lies at time j / rate from the
    first frame, which keeps its number, up to the time of the last frame (N
    frames become floor((N - 1) new / old) + 1).  Translations and lone angles
    (joints with one or two rotation channels, unwrapped) go through the
    polyphase filter of ``scipy.signal.resample_poly`` (Kaiser window; it also
    removes what the lower rate cannot hold), less the line through the
    first and last frames, which is added back, so that a constant or a
    straight line stays exact (a joint that holds still is copied).  A joint
    with three rotation channels is
    resampled as a rotation: its unit quaternions (signs made continuous) go
    through the same filter and are normalised, or, going to a higher rate
    with ``rotations="slerp"``, are interpolated by SLERP between the frames
    around each new one; the Euler angles written continue from the first
    frame's, in the channel's range, never crossing a wrap the take did not
    cross.  SLERP keeps each new frame on the arc between two old ones but
    misses their curvature: from 30 back to 120 Hz it is 0.8-1.9 degrees off
    on CMU walks where the filter is 0.1.
    """
    up, down = sg.rational_ratio(rate, motion.frame_rate)
    header = tuple(
        f"Frame Time: {format_number(1.0 / float(rate))}" if line.lower().startswith("frame time") else line
        for line in motion.header
    )
    skeleton = motion.skeleton
    n = motion.frames
    if n == 0:
        return motion.replace(values=motion.values, frame_rate=float(rate), header=header)
    n_out = (n - 1) * up // down + 1  # the frames within the take's span (resample_poly may add up to one more)
    values = np.empty((n_out, len(motion.channels)))
    groups = skeleton.euler_groups()
    turned = {int(c) for _, _, cols in groups for c in cols.ravel()}
    lone_rotations, others = _columns(motion, None)
    lone_rotations = [c for c in lone_rotations if c not in turned]
    period = skeleton.period
    if others:
        values[:, others] = _resampled_lines(motion.values[:, others], up, down, workers)
    if lone_rotations:
        angles = motion.values[:, lone_rotations]
        values[:, lone_rotations] = _wrap_into(
            _resampled_lines(_unwrapped(angles, period), up, down, workers), *_ranges(angles), period
        )
    degrees = skeleton.angle_unit == "deg"
    for order, extrinsic, cols in groups:
        angles = motion.values[:, cols]  # (frames, joints, 3)
        q = rot.unroll_quaternions(rot.euler_to_quaternions(angles, order, extrinsic=extrinsic, degrees=degrees))
        if rotations == "slerp" and up > down and n > 1:
            at = np.arange(n_out) * down / up
            i = np.minimum(np.floor(at).astype(np.intp), n - 2)
            q_out = rot.slerp(q[i], q[i + 1], (at - i)[:, None])
        else:
            lines = _resampled_lines(q.reshape(n, -1), up, down, workers).reshape(n_out, -1, 4)
            q_out = lines / np.linalg.norm(lines, axis=-1, keepdims=True)
        turned_angles = rot.quaternions_to_euler(q_out, order, extrinsic=extrinsic, degrees=degrees)
        # of the equivalent Euler triples, each frame's nearest the one before, from the take's first frame on
        path = rot.unroll_euler(np.concatenate([angles[:1], turned_angles]), order, degrees=degrees)[1:]
        _steady_near_gimbal_lock(path, angles, q_out, (order, extrinsic, degrees), up, down, workers)
        # a joint that holds still is copied: through quaternions its angles would come back to rounding
        path[:, np.all(angles == angles[:1], axis=(0, 2))] = angles[0, np.all(angles == angles[:1], axis=(0, 2))]
        flat = path.reshape(n_out, -1)
        values[:, cols.ravel()] = _wrap_into(flat, *_ranges(angles.reshape(n, -1)), period)
    values.flags.writeable = False
    return motion.replace(values=values, frame_rate=float(rate), header=header)


# ---------------------------------------------------------------------------
# gaps


class Gap(NamedTuple):
    """A run of missing values in one channel: frames ``first`` .. ``last`` (frame numbers)."""

    joint: str
    dof: str
    first: int
    last: int

    def __str__(self) -> str:
        return f"{self.joint} {self.dof} frames {self.first}-{self.last}"


def find_gaps(motion: Motion) -> list[Gap]:
    """Every run of NaN in the motion's channels, by channel then frame."""
    channels = motion.channels
    return [
        Gap(channels[column][0], channels[column][1], motion.first_frame + first, motion.first_frame + stop - 1)
        for column, first, stop in sg.nan_runs(motion.values).tolist()
    ]


def _fill_slerp(values: np.ndarray, motion: Motion, joints: Iterable[str] | None, max_frames: int) -> set[int]:
    """Fills, in values, the gaps of the chosen joints with three rotation channels by SLERP between
    the frames around each gap (all three channels over frames where any is NaN); returns their columns."""
    skeleton = motion.skeleton
    chosen = skeleton.joint_names if joints is None else tuple(joints)
    degrees, period = skeleton.angle_unit == "deg", skeleton.period
    n = len(values)
    done: set[int] = set()
    for order, extrinsic, cols in skeleton.euler_groups(chosen):
        done.update(int(c) for c in cols.ravel())
        missing = np.isnan(values[:, cols]).any(axis=2)  # (frames, joints)
        runs = sg.nan_runs(np.where(missing, np.nan, 0.0))
        runs = runs[(runs[:, 1] > 0) & (runs[:, 2] < n) & (runs[:, 2] - runs[:, 1] <= max_frames)]
        if not len(runs):
            continue
        joint, start, stop = runs.T
        # each gap as its key a, its frames, then a NaN row, so that unroll_euler restarts at every key
        lengths = stop - start
        rows = np.concatenate([np.arange(s - 1, e + 1) for s, e in zip(start, stop)])
        owner = np.repeat(np.arange(len(runs)), lengths + 2)
        a, b = start[owner] - 1, stop[owner]
        t = (rows - a) / (b - a)
        keys = values[np.stack([a, b])[:, :, None], cols[joint[owner]][None]]  # (2, rows, 3)
        q = rot.euler_to_quaternions(keys, order, extrinsic=extrinsic, degrees=degrees)
        angles = rot.quaternions_to_euler(rot.slerp(q[0], q[1], t), order, extrinsic=extrinsic, degrees=degrees)
        first = rows == a
        angles[first] = keys[0][first]  # the key itself, as stored
        angles[rows == b] = np.nan  # the separator
        path = rot.unroll_euler(angles, order, degrees=degrees)
        inside = (rows > a) & (rows < b)
        for j in np.unique(joint):
            mine = inside & (joint[owner] == j)
            stored = values[:, cols[j]]
            values[rows[mine], cols[j][:, None]] = _wrap_into(path[mine], *_ranges(stored), period).T
    return done


@step("fill_gaps", "fill short runs of missing values (NaN or dropped frames); longer ones are listed, not invented")
def fill_gaps(
    motion: Motion,
    *,
    max_gap: Annotated[float, "longest run filled, in seconds"] = 0.25,
    method: Annotated[
        Literal["slerp", "linear", "cubic"],
        "slerp: rotations of three-channel joints by SLERP, the rest linearly; or linear or cubic spline throughout",
    ] = "slerp",
    joints: Annotated[Joints, "joints to fill (default: all)"] = None,
    drop: Annotated[Frames, "frames FIRST:LAST to treat as dropped (missing) first"] = None,
) -> Motion:
    """A new motion whose short gaps are filled.

    A gap is a run of NaN in a channel (or the frames ``drop`` marks as
    dropped, for the chosen joints).  One of at most ``max_gap`` seconds with
    a frame on both sides is filled: "linear" on the line between those frames
    (numpy.interp), "cubic" on the cubic spline (scipy's CubicSpline,
    not-a-knot) through every frame of the stretch between the gaps left
    unfilled, or "slerp": a joint with three rotation channels by SLERP
    between the rotations around the gap (over every frame where any of its
    three channels is missing), its other channels linearly.  Rotation
    channels are unwrapped first (so a gap across +-180 degrees is bridged the
    short way) and the filled angles wrapped into the channel's range.  Gaps
    at the ends or longer are left NaN and logged (:func:`find_gaps` lists
    them); every frame that was not missing stays bit-identical.
    """
    if not max_gap >= 0:
        raise ValueError(f"max_gap must be a duration in seconds (0 or more), got {max_gap!r}")
    max_frames = math.floor(max_gap * motion.frame_rate + 1e-9)
    rotations, others = _columns(motion, joints)
    values = motion.values.copy()
    if drop is not None:
        first, last = drop
        if not motion.first_frame <= first <= last <= motion.last_frame:
            raise ValueError(
                f"drop: frames {first}:{last} are not within the motion's frames "
                f"{motion.first_frame}..{motion.last_frame}"
            )
        rows = slice(first - motion.first_frame, last - motion.first_frame + 1)
        values[rows, rotations + others] = np.nan
    slerped = _fill_slerp(values, motion, joints, max_frames) if method == "slerp" else set()
    how = "cubic" if method == "cubic" else "linear"
    period = motion.skeleton.period
    for columns, turning in (([c for c in rotations if c not in slerped], True), (others, False)):
        if not columns:
            continue
        block = values[:, columns]
        source = _unwrapped(block, period) if turning else block
        filled = sg.fill_gaps(source, max_frames, how, axis=0).values
        if turning:
            filled = _wrap_into(filled, *_ranges(block), period)
        new = np.isnan(block) & ~np.isnan(filled)
        block[new] = filled[new]
        values[:, columns] = block
    values.flags.writeable = False
    result = motion.replace(values=values)
    chosen = set(result.skeleton.joint_names if joints is None else joints)
    left = [gap for gap in find_gaps(result) if gap.joint in chosen]  # the others were not asked for
    if left:
        shown = ", ".join(map(str, left[:5])) + (f" and {len(left) - 5} more" if len(left) > 5 else "")
        log.warning(
            "fill_gaps: %d gap(s) at the ends or longer than %g s (%d frames) left missing: %s",
            len(left),
            max_gap,
            max_frames,
            shown,
        )
    return result
