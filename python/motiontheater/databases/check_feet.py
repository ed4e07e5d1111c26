"""The take check's findings on the legs: planted feet that slide (skate), feet below the floor
(penetration), a floor away from level zero, knees bent backwards, and a frame rate that a
steady walk's strides disagree with (rate).

The legs, the floor and the footplants are found as footskate cleanup finds them
(:mod:`motiontheater.feet`), so that what the check calls a skate is what the cleanup fixes, and
the recipe for it is the ``cleanup`` step over the plant's frames and the fades around them.
Feet in the floor are reported, not fixed: where the floor is depends on the frames the floor is
fitted to, and a recipe that moves the legs on a guess of it is no repair.  A
take without recognisable legs (a hand, a chain of bones) has no findings here.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from mtcore.check import LegCheck, leg_measures
from mtcore.kinematics import Kinematics

from ..feet.contacts import run_peaks
from ..feet.footskate import prepare
from ..feet.legs import Ground, LegArrays, resolve_legs
from ..model.motion import Motion
from ..model.rig import body_view
from ..model.skeleton import Skeleton
from ..model.vectors import lengths, median, spans
from .findings import Finding

SKATE_M = 0.12
"""Metres a planted heel or ball must slide over its plant to skate (a real plant moves 1-5 cm as
the foot settles; 12 cm is a foot that visibly slides); three times as far is high."""
SKATE_HEIGHT, SKATE_SPEED, SKATE_SECONDS = 0.03, 0.6, 0.25
SKATE_AROUND = 2.0
"""A heel or ball within 3 cm of its lowest in the SKATE_AROUND seconds before and after, slower
than 0.6 m/s, for 0.25 s or more, is on the floor (a swinging foot passes lower, but faster)."""
PENETRATION_M = 0.05
"""Metres a heel, ball or toe tip must sink below where it rests on the floor, for
PENETRATION_SECONDS or more, to be in the floor."""
PENETRATION_SECONDS = 0.1
UPRIGHT_SHARE = 0.8
"""The share of a take's frames that must stand along another axis than y for the check to say so."""
FLOOR_M = 0.15
"""Metres the floor the feet rest on may lie from level zero before the check says so (a joint
centre rests a few centimetres above the sole)."""
KNEE_BACK_DEG = 20.0
"""Degrees a knee may bend backwards (past straight; 5-10 degrees is human) before it is bent
backwards; 45 is high."""
KNEE_FOLDED_DEG = 90.0
"""Bends the other way deeper than this are not counted: there the knee's hinge turns with the
thigh and says nothing of which way the knee bends."""
FOOT_ACROSS = math.cos(math.radians(45))
"""A foot within 45 degrees of square to the shin tells which way the knee bends."""
STRIDE_ALIKE = 0.75
"""How alike the legs' alternation must be from one stride to the next (its autocorrelation at
the stride) for the stride to tell the take's rate: a steady walk or run."""
STRIDE_HIPS = 0.6
"""Hip heights a stride must cover (a step on the spot tells no speed)."""
STRIDE_SPEED_SHARE = 0.8
"""The walkers and runners of the real takes here go at 0.5-1.7 (median 0.8) times the speed
Alexander's relation gives for their stride, lambda / h = 2.3 (v^2 / g h)^0.3 (h the hip
height; Alexander 1984): the check takes 0.8, and names the rates 0.45-1.8 would give."""
STRIDE_SPEED_RANGE = (0.45, 1.8)
RATE_FACTOR = 2.0
"""A rate the stride puts this many times off the file's is reported (the real takes lie within
1.7 of it; a Frame Time written for another rate is off by 2 or 4).  It is reported, not fixed:
only the capture's notes can say which rate it was; ``retime`` is the step that sets it."""
BLEND_SECONDS = 0.2 + 0.1
"""The cleanup's fades (its blend) and root smoothing: a recipe's cleanup range reaches this far
beyond the frames it fixes, so that the adjustments fade within it."""


def turned_joints(skeleton: Skeleton) -> list[int]:
    """The joints whose world rotations :func:`leg_findings` reads from the take's kinematics: the
    ankles', which turn the heels, and where the rest pose gives no heel, the legs' parents, which
    turn the legs the heels are derived from (none where the check finds no legs)."""
    try:
        legs = resolve_legs(skeleton)
        return [int(j) for j in (*legs.rotators[:, 2], *(legs.parents if legs.heels_missing.any() else ()))]
    except ValueError:
        return []


def leg_findings(motion: Motion, take: str, meters: float, kinematics: Kinematics | None = None) -> list[Finding]:
    """The findings on the legs of a take whose length unit is ``meters`` metres; ``kinematics``:
    the take's forward kinematics, where the caller has them."""
    if motion.frames < 2:
        return []
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the take's unit and rig are the check's own findings
            arrays, ground, mpu = prepare(motion, meters_per_unit=meters, kinematics=kinematics)
    except ValueError:
        return []  # no legs, or none that are numbers: nothing to judge here
    context = _Legs(motion, take, arrays, ground, mpu)
    return (
        context.upright()
        + context.skates()
        + context.penetrations()
        + context.floor()
        + context.knees()
        + context.rhythm()
    )


class _Legs:
    def __init__(self, motion: Motion, take: str, arrays: LegArrays, ground: Ground, mpu: float):
        self.motion, self.take, self.arrays, self.ground, self.mpu = motion, take, arrays, ground, mpu
        self.up = np.asarray(ground.up)
        view = body_view(motion).motion  # the cleanup moves the body: it needs its translation
        self.movable = {"tx", "ty", "tz"} <= set(view.skeleton.dofs("root"))
        rate = motion.frame_rate
        # the heel or ball on the floor: within SKATE_HEIGHT of its lowest in the SKATE_AROUND
        # seconds around (not the fitted floor, which moves with the frames that rest: a foot that
        # slides rests in none; nor its lowest over the take, which a crouch or a step down sets
        # elsewhere), slower than SKATE_SPEED (a swinging foot passes lower, but faster)
        settings = LegCheck(
            ground.up, ground.slope, ground.level, mpu, rate, max(1, round(SKATE_AROUND * rate)),
            SKATE_HEIGHT, SKATE_SPEED, FOOT_ACROSS, KNEE_FOLDED_DEG,
        )  # fmt: skip
        self.measures = leg_measures(
            arrays.points, arrays.hips, ground.clearance, arrays.legs.points[:, 4] >= 0, settings
        )

    def frame(self, row: int) -> int:
        return self.motion.first_frame + int(row)

    def cleanup(self, first: int, last: int, plant: tuple[str, str] | None = None) -> tuple:
        """The cleanup step over rows first..last and the fades around them, holding the foot's
        point (foot, "heel" or "ball") over them where given; none where the body cannot move."""
        if not self.movable:
            return ()
        margin = round(BLEND_SECONDS * self.motion.frame_rate) + 1
        a, b = max(first - margin, 0), min(last + margin, self.motion.frames - 1)
        options: dict = {"frames": [self.frame(a), self.frame(b)]}
        if plant is not None:
            options["plants"] = [f"{plant[0]}:{plant[1]}:{self.frame(first)}:{self.frame(last)}"]
        return (("cleanup", options),)

    def skates(self) -> list[Finding]:
        """Runs of frames in which a heel or ball stays on the floor and slower than a step, over
        which it slides farther than SKATE_M: found without the footplants, which a slide splits."""
        shortest = max(2, round(SKATE_SECONDS * self.motion.frame_rate))
        drift = self.measures.drift.reshape(-1, self.motion.frames)  # each leg's heel, then its ball
        if not np.fmax.reduce(drift, axis=None, initial=0.0) * self.mpu > SKATE_M:
            return []  # no point slides so far (NaN off the floor left out)
        slides: list[list] = [[] for _ in self.arrays.legs.feet]  # per foot: (first row, last row, metres, point)
        for row, s, e, peak in run_peaks(~np.isnan(drift), drift):
            if e - s >= shortest and peak * self.mpu > SKATE_M:
                slides[row // 2].append((s, e - 1, peak * self.mpu, ("heel", "ball")[row % 2]))
        out = []
        for foot, found in zip(self.arrays.legs.feet, slides):
            for first, last, slide, point in _merged(found):
                out.append(
                    Finding(
                        self.take, "skate", (foot,), self.frame(first), self.frame(last),
                        "high" if slide > 3 * SKATE_M else "medium", round(slide, 6), "m",
                        f"the {point} of {foot} slides {slide:.3g} m along the floor", None,
                        self.cleanup(first, last, (foot, point)),
                    )
                )  # fmt: skip
        return out

    def penetrations(self) -> list[Finding]:
        shortest = max(1, round(PENETRATION_SECONDS * self.motion.frame_rate))
        depth = self.measures.depth * self.mpu
        feet = self.arrays.legs.feet
        out = []
        # NaN where the foot is a gap: it sinks nowhere (NaN compares false)
        for i, s, e, worst in run_peaks(depth > PENETRATION_M, depth):
            if e - s >= shortest:
                out.append(
                    Finding(
                        self.take, "penetration", (feet[i],), self.frame(s), self.frame(e - 1), "medium",
                        round(worst, 6), "m", f"{feet[i]} goes {worst:.3g} m into the floor",
                    )
                )  # fmt: skip
        return out

    def upright(self) -> list[Finding]:
        """The axis the character stands along (the hips above the ankles), where it is not y,
        the up axis of ASF/AMC (Acclaim's convention) and the one BVH readers take: upside down
        (high), along x (medium), along z (medium for ASF/AMC; low for BVH, where z-up exports
        are common and motiontheater reads them standing).  Told where it stands so in
        UPRIGHT_SHARE of its frames (a take that lies down for a while stands otherwise)."""
        counts = self.measures.standing  # frames along x, -x, y, -y, z, -z
        total = int(counts.sum())
        if not total:
            return []
        most = int(np.argmax(counts))
        share = int(counts[most]) / total
        if most == 2 or share < UPRIGHT_SHARE:
            return []
        name = ("-" if most % 2 else "") + "xyz"[most // 2]
        bvh = self.motion.skeleton.convention == "bvh"
        if name == "-y":
            severity, what = "high", "upside down: readers show it standing on its head"
        elif name in ("x", "-x"):
            severity, what = "medium", "along x, which no reader takes as up: they show it lying on its side"
        elif bvh:
            severity, what = (
                "low",
                (
                    f"along {name}, as z-up exports write it: motiontheater reads it standing, but BVH readers "
                    "that take y as up (Blender's importer, three.js's BVHLoader) show it lying down"
                ),
            )
        else:
            severity, what = (
                "medium",
                f"along {name}: ASF/AMC is y-up (Acclaim's convention), so readers show it lying down",
            )
        return [
            Finding(
                self.take, "up", (), self.motion.first_frame, self.motion.last_frame, severity,
                round(share * 100, 2), "%",
                f"the character stands {what} (its hips above its ankles along {name} in {share:.0%} of the frames)",
            )
        ]  # fmt: skip

    def floor(self) -> list[Finding]:
        level = self.ground.level * self.mpu
        if abs(level) <= FLOOR_M:
            return []
        axis = "".join(f"{'-' if v < 0 else ''}{'xyz'[i]}" for i, v in enumerate(self.ground.up) if abs(v) > 0.5)
        return [
            Finding(
                self.take, "floor", (), self.motion.first_frame, self.motion.last_frame, "low", round(level, 6),
                "m", f"the feet rest on a floor {abs(level):.3g} m {'above' if level > 0 else 'below'} level zero "
                f"(up is {axis or 'tilted'})",
            )
        ]  # fmt: skip

    def knees(self) -> list[Finding]:
        """Knees bent backwards: a knee bends the shin away from where the foot points, so the
        turn from thigh to shin is the other way round than the turn from shin to foot, at any
        bend and any hip (told only where the foot stands across the shin, and the knee is not
        folded: see :func:`mtcore.check.leg_measures`)."""
        out = []
        legs, back = self.arrays.legs.legs, self.measures.back
        for i, s, e, worst in run_peaks(back > KNEE_BACK_DEG, back):
            out.append(
                Finding(
                    self.take, "knee", (legs[i].knee,), self.frame(s), self.frame(e - 1),
                    "high" if worst > 45 else "medium", round(worst, 6), "deg",
                    f"{legs[i].knee} bends {worst:.3g} deg backwards, past what a knee does",
                )
            )  # fmt: skip
        return out

    def rhythm(self) -> list[Finding]:
        """The rate a steady walk or run's stride gives, where it is RATE_FACTOR off the file's:
        the frames of a stride and the ground it covers do not depend on the rate; the speed
        they make does, and a person striding that far goes at a known speed."""
        ankles = self.arrays.points[:, :, 1]
        heights = ankles @ self.up  # not finite where a coordinate is not (inf times 0 is NaN)
        if len(ankles) != 2 or not np.isfinite(heights).all():
            return []
        hips = (self.arrays.hips[0] + self.arrays.hips[1]) * 0.5  # their mean
        along = hips @ self.up
        ground = hips - along[:, None] * self.up
        hip = median(along - np.minimum(heights[0], heights[1])) * self.mpu
        # no stride is longer than the ground the hips cover: where that is too short, no search
        # (the takes that do not walk or run, a third of those here)
        if not (hip > 0 and math.hypot(*spans(ground)) * self.mpu > STRIDE_HIPS * hip):
            return []
        frames = _stride(heights[0] - heights[1])
        if frames is None:
            return []
        stride = median(lengths(ground[frames:] - ground[:-frames])) * self.mpu
        if not stride > STRIDE_HIPS * hip:
            return []
        expected = STRIDE_SPEED_SHARE * math.sqrt(9.81 * hip) * (stride / (2.3 * hip)) ** (1 / 0.6)
        rate = self.motion.frame_rate
        speed = stride * rate / frames
        likely = expected * frames / stride  # the rate at which the stride takes that speed
        if 1 / RATE_FACTOR < likely / rate < RATE_FACTOR:
            return []
        low, high = (likely * share / STRIDE_SPEED_SHARE for share in STRIDE_SPEED_RANGE)
        return [
            Finding(
                self.take, "rate", (), self.motion.first_frame, self.motion.last_frame, "medium",
                _digits(likely), "Hz",
                f"strides of {stride:.2g} m take {frames / rate:.2g} s at {rate:g} Hz, {speed:.2g} m/s; people who "
                f"stride that far go at about {expected:.2g} m/s: the take was likely recorded at about "
                f"{_digits(likely):g} Hz ({_digits(low):g}-{_digits(high):g} Hz, as walkers' speeds for a stride "
                f"vary), not {rate:g}; where the capture's notes agree, motiontheater retime --rate HZ sets it",
            )
        ]  # fmt: skip


def _digits(x: float) -> float:
    """x to two significant digits (140.0, not 1.4e+02 as :g would print it)."""
    return float(f"{x:.2g}")


def _stride(alternation: np.ndarray) -> int | None:
    """The frames of one stride: the first peak of the autocorrelation of the left foot's height
    less the right's, where it is STRIDE_ALIKE or more and the take holds two strides."""
    n = len(alternation)
    x = alternation - alternation.mean()
    energy = float(x @ x)
    if n < 8 or not energy > 0:
        return None
    half = n // 2  # the lags a take of two strides can show
    size = _smooth_size(n + half)  # no wrap-around into those lags
    spectrum = np.fft.rfft(x, size)
    alike = np.fft.irfft(spectrum.real**2 + spectrum.imag**2, size)[:half] / energy
    alike /= 1 - np.arange(half) / n  # the share of the take each lag compares
    below = np.flatnonzero(alike < 0)
    if not len(below):
        return None
    lag = int(below[0] + np.argmax(alike[below[0] :]))
    return lag if alike[lag] >= STRIDE_ALIKE else None


def _smooth_size(least: int) -> int:
    """The smallest m 2^k >= least for m in 1, 3, 5, 9, 15: a length pocketfft is fast at, at
    most a quarter longer than ``least`` (a power of two can be twice as long)."""
    return min(m << max(-(-least // m) - 1, 0).bit_length() for m in (1, 3, 5, 9, 15))


def _merged(slides: list[tuple[int, int, float, str]]) -> list[tuple[int, int, float, str]]:
    """Overlapping slides of one foot's heel and ball as one, the farther point's."""
    out: list[tuple[int, int, float, str]] = []
    for first, last, slide, point in sorted(slides):
        if out and first <= out[-1][1]:
            a, b, worst, name = out[-1]
            out[-1] = (a, max(b, last), *((slide, point) if slide > worst else (worst, name)))
        else:
            out.append((first, last, slide, point))
    return out
