"""Dropped frames: steps of a take that hold two or more steps of motion, the frames between
them missing (a stream that lost packets, a capture that skipped a camera frame).

A missing frame shows where the body is, not in the file's angles: every joint moves as far
from one frame to the next as in two steps, while the steps before and after move as usual.
Near gimbal lock Euler angles swing while the joints stay put, so the joints' positions are
compared (forward kinematics, in metres), each coordinate counting by its own noise (the
frame-to-frame roughness over the take), so that only a step the noise cannot explain is told.
The mean m of the changes into and out of a step and the step's change d give, summed over the
coordinates in units of their noise, the evidence that the step holds k steps of motion rather
than one: sum ((d - m)^2 - (d - k m)^2), where the k steps fit well (the whole body moves k
steps, not one joint farther); the kernel :func:`mtcore.check.pace` computes the sums, in one
pass over the rows.  Nothing is made up to fix it: the finding is told, with how
long the missing time was.
"""

from __future__ import annotations

import numpy as np

from mtcore import check as kernel
from mtcore.kinematics import Kinematics, world_kinematics

from ..model.motion import Motion
from .findings import Finding

DROP_EVIDENCE = 25.0
"""How much better "frames are missing between these two" explains a step than "the take moves
on evenly", in units of the noise (a log-likelihood ratio of 12.5: five sigma)."""
DROP_FIT = 0.5
"""The most of the step's misfit as one step of motion that frames missing may leave: the whole
body moves as many steps, not one joint farther (a teleport of the root, a spike of a hand)."""
MOST_MISSING = 5
"""The most frames told missing in one step (a longer loss is a cut, not a dropped frame)."""
NOISE_M = 0.0001
"""The least noise a coordinate is taken to have, metres (a take of few digits, or synthetic)."""
AROUND = ("gap", "repeated")
"""Findings whose frames move unevenly for their own reason: no step within them is told (a
frame repeated in place of a lost one, then a step of two: the repeat is the finding).  A flip
moves no joint, and a held channel's catching up moves only the joints below it: the fit of
the whole body tells them apart."""
CONSEQUENCES = ("jump", "teleport", "spike")
"""Findings that frames missing make (a fast hand, the root, jump as far as in two frames):
within a frame of a step with frames missing, the finding is the missing frames."""


def dropped_findings(
    motion: Motion, take: str, found: list[Finding], kinematics: Kinematics | None = None
) -> tuple[list[Finding], list[Finding]]:
    """The steps of the take with frames missing between them (but beside the ``found``
    findings that explain an uneven step), and ``found`` without the jumps those missing frames
    make; ``kinematics``: the take's forward kinematics, where the caller has them."""
    pace = step_pace(motion, kinematics)
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = pace.paced / pace.moved
    steps = np.clip(np.round(np.where(np.isnan(ratio), 0.0, ratio)), 2.0, MOST_MISSING + 1.0)

    def misfit(s: np.ndarray | float) -> np.ndarray:
        return pace.stepped - 2 * s * pace.paced + s * s * pace.moved

    one, many = misfit(1.0), misfit(steps)
    taken = (one - many > DROP_EVIDENCE) & (many < DROP_FIT * one)
    quiet = np.ones(motion.frames, bool)  # the rows no other finding explains a step beside
    for f in found:
        a, b = f.first - motion.first_frame, f.last - motion.first_frame
        if f.kind in AROUND:
            quiet[max(a - 2, 0) : max(b + 3, 0)] = False
    out: list[Finding] = []
    made: set[int] = set()
    quiet[:-1] &= quiet[1:]  # and the row after
    for row in map(int, np.flatnonzero(taken & quiet)):
        a, b = motion.first_frame + row, motion.first_frame + row + 1
        made.update((a - 1, a, b, b + 1))
        missing = int(steps[row]) - 1
        seconds = missing / motion.frame_rate
        out.append(
            Finding(
                take, "dropped", (), a, b, "low", round(seconds, 6), "s",
                f"the body moves {ratio[row]:.2g} times as far from frame {a} to {b} as into and out of them: "
                f"{missing} frame(s) ({seconds * 1000:.3g} ms) seem missing between them (told, not fixed: no "
                "frame is made up)",
            )
        )  # fmt: skip
    kept = [f for f in found if not (f.kind in CONSEQUENCES and f.last - f.first <= 2 and {f.first, f.last} <= made)]
    return out, kept


def step_pace(motion: Motion, kinematics: Kinematics | None = None) -> kernel.Pace:
    """The :func:`mtcore.check.pace` of the joints' positions, each coordinate weighted by its
    noise in metres: the frame-to-frame roughness over the take, at least NOISE_M.  ``kinematics``:
    the take's forward kinematics, where the caller has them (the check holds a long take's
    frames a piece at a time: :mod:`.pieces`)."""
    rows = motion.frames
    if rows < 4:
        return kernel.Pace(np.zeros(rows), np.zeros(rows), np.zeros(rows))
    if kinematics is None:
        kinematics = world_kinematics(motion.values, motion.skeleton.tree, workers=1)
    places = kinematics.positions.reshape(rows, -1)  # in file units: the unit goes into the weights
    meters = motion.skeleton.meters_per_unit
    squares, counts = np.zeros(places.shape[1]), np.zeros(places.shape[1], np.uintp)
    kernel.roughness(places, squares, counts)  # a gap's left out
    with np.errstate(invalid="ignore", divide="ignore"):
        noise = squares / counts / 1.5 * meters**2  # the variance of one coordinate, m^2
    noise[np.isnan(noise)] = 0.0  # a coordinate never finite beside its neighbours
    # d - m = 1.5 x[t+1] - 1.5 x[t] + 0.5 x[t-1] - 0.5 x[t+2]: five times the variance of one
    return kernel.pace(places, meters**2 / (5.0 * (noise + NOISE_M**2)))
