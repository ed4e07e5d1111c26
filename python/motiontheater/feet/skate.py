"""Footskate metrics of a take: how much its planted feet slide, sink and float, and how often they skate.

Per foot, over its heel and ball (heights are above where each point rests
on the floor, see :mod:`motiontheater.feet.legs`; plants are a contacts table,
detected unless given):

- ``plants``: the footplants of the heel and of the ball;
- ``sliding_mean_mm``, ``sliding_max_mm``: over every planted frame, the
  horizontal distance of the planted point from where it was at its plant's
  first frame;
- ``skating_ratio``: the share of frame steps t -> t+1 (frames - 1 of them)
  in which the foot skates, as motion-generation papers count it (GMD,
  OmniControl): a point within 5 cm of the floor at t and t+1 whose
  horizontal speed and that speed's moving average (5 frames at the papers'
  20 Hz, i.e. 0.25 s at the take's rate) both exceed 0.5 m/s.  Real walks
  score 10-40 % on it, before a cleanup and after: a swinging foot passes the
  floor lower than 5 cm and faster than 0.5 m/s, and a cleanup leaves swing
  alone (a planted point is never that fast: the sliding says how still it is);
- ``planted_skating_ratio``: the same count over the frame steps in which
  the heel or the ball is planted (both frames of the step in its plant): the
  share of them in which a planted point skates (0 without planted steps).
  This is how "skating on the detected plants" is judged; on a take's own
  detected plants it is 0 by construction (detection plants no point faster
  than 0.45 m/s, and skating needs 0.5 m/s), so it tells something where the
  table plants feet that move: an edited table, or another take's;
- ``penetration_mm``: the deepest any of its heel, ball and toe tip goes
  below where it rests, over all frames;
- ``float_mm``: the mean height of planted points over their plants.
"""

from __future__ import annotations

import json
import os
from dataclasses import asdict, dataclass

import numpy as np

from ..model.motion import Motion
from ..model.registry import Joints
from .contacts import PLANT_POINTS, Contacts, runs
from .footskate import contacts_of, prepare
from .legs import Ground, LegArrays, Legs

SKATE_HEIGHT = 0.05  # m
SKATE_SPEED = 0.5  # m/s
SKATE_WINDOW = 5 / 20.0  # s: 5 frames at 20 Hz


@dataclass(frozen=True)
class FootMetrics:
    """The metrics of one foot (see the module docstring)."""

    foot: str
    plants: dict[str, int]
    sliding_mean_mm: float
    sliding_max_mm: float
    skating_ratio: float
    planted_skating_ratio: float
    penetration_mm: float
    float_mm: float


@dataclass(frozen=True)
class SkateReport:
    """Metrics per foot (see the module docstring) of a take of ``frames`` frames at ``frame_rate``."""

    feet: tuple[FootMetrics, ...]
    frames: int
    frame_rate: float

    def worst(self, name: str) -> float:
        """The largest value of metric ``name`` (e.g. "sliding_max_mm") over the feet."""
        return max((float(getattr(f, name)) for f in self.feet), default=0.0)

    def as_dict(self) -> dict:
        """The report as plain data (what ``--json`` prints)."""
        return {"frames": self.frames, "frame_rate": self.frame_rate, "feet": [asdict(f) for f in self.feet]}

    def to_json(self) -> str:
        """The report as JSON text."""
        return json.dumps(self.as_dict(), indent=2)

    def text(self) -> str:
        """The report as a Markdown table."""
        lines = [
            "| foot | plants (heel, ball) | sliding mean mm | sliding max mm | skating % | skating planted % "
            "| penetration mm | float mm |",
            "|---|---|---:|---:|---:|---:|---:|---:|",
        ]
        for f in self.feet:
            numbers = (
                f.sliding_mean_mm,
                f.sliding_max_mm,
                100 * f.skating_ratio,
                100 * f.planted_skating_ratio,
                f.penetration_mm,
                f.float_mm,
            )
            # rounded first, then + 0.0: a value that rounds to nothing prints as 0.00, not -0.00
            shown = " | ".join(f"{round(v, 2) + 0.0:.2f}" for v in numbers)
            lines.append(f"| {f.foot} | {f.plants['heel']}, {f.plants['ball']} | {shown} |")
        return "\n".join(lines)


def _horizontal(p: np.ndarray, up: np.ndarray) -> np.ndarray:
    return p - (p @ up)[..., None] * up


def _moving_average(x: np.ndarray, width: int) -> np.ndarray:
    """Centred mean over ``width`` samples (odd), zeros beyond the ends (as scipy's mode 'constant')."""
    if width <= 1 or len(x) == 0:
        return x.astype(float)
    half = width // 2
    padded = np.r_[np.zeros(half), x, np.zeros(half)]
    c = np.r_[0.0, np.cumsum(padded)]
    return (c[width:] - c[:-width]) / width


def measure(
    arrays: LegArrays, ground: Ground, contacts: Contacts, frame_rate: float, meters_per_unit: float
) -> SkateReport:
    """The metrics of a take's legs (:func:`~motiontheater.feet.legs.leg_arrays`) on a ground with a contacts table."""
    legs = arrays.legs
    up = np.asarray(ground.up)
    masks = contacts.masks(legs)
    heights = ground.heights(arrays.points) * meters_per_unit  # (legs, frames, 3) heel, ball, tip, metres
    frames = arrays.points.shape[1]
    window = max(1, round(SKATE_WINDOW * frame_rate) // 2 * 2 + 1)
    feet = []
    for i, foot in enumerate(legs.feet):
        slides = []
        skating = np.zeros(max(frames - 1, 0), bool)
        planted_skating, planted_steps = np.zeros_like(skating), np.zeros_like(skating)
        for k, column in enumerate((3, 2)):
            p = _horizontal(arrays.points[i, :, column], up)
            starts, ends = runs(masks[i, :, k])
            slides += [np.linalg.norm(p[s:e] - p[s], axis=-1) for s, e in zip(starts, ends)]
            if frames < 2:
                continue
            speed = np.linalg.norm(np.diff(p, axis=0), axis=-1) * frame_rate * meters_per_unit
            low = heights[i, :, k] < SKATE_HEIGHT
            skates = low[:-1] & low[1:] & (speed > SKATE_SPEED) & (_moving_average(speed, window) > SKATE_SPEED)
            held = masks[i, :-1, k] & masks[i, 1:, k]  # plants never touch: both frames are of one plant
            skating |= skates
            planted_skating |= skates & held
            planted_steps |= held
        slide = np.concatenate(slides) * meters_per_unit * 1000 if slides else np.zeros(0)
        points = [0, 1, 2] if legs.points[i, 4] >= 0 else [0, 1]
        depth = -float(np.nanmin(heights[i][:, points])) if frames else 0.0
        planted = heights[i, :, :2][masks[i]]
        steps = max(frames - 1, 1)
        feet.append(
            FootMetrics(
                foot=foot,
                plants={point: len(contacts.of(foot, point)) for point in PLANT_POINTS},
                sliding_mean_mm=float(slide.mean()) if len(slide) else 0.0,
                sliding_max_mm=float(slide.max()) if len(slide) else 0.0,
                skating_ratio=float(skating.sum() / steps),
                planted_skating_ratio=float(planted_skating.sum() / max(planted_steps.sum(), 1)),
                penetration_mm=max(depth, 0.0) * 1000,
                float_mm=float(np.mean(np.maximum(planted, 0.0))) * 1000 if len(planted) else 0.0,
            )
        )
    return SkateReport(tuple(feet), frames, frame_rate)


def skate_metrics(
    motion: Motion,
    contacts: Contacts | str | os.PathLike | None = None,
    *,
    legs: Legs | Joints = None,
    up: str | None = None,
    floor: float | None = None,
    ground: Ground | None = None,
    meters_per_unit: float | None = None,
) -> SkateReport:
    """Footskate metrics of a motion (see the module docstring).

    ``contacts``: a table or its CSV (default: detected on this motion);
    ``legs``: as for cleanup, or the :class:`~motiontheater.feet.legs.Legs` of a
    cleanup (``Cleanup.legs``, so that heels derived from the input are
    kept); ``ground``: the floor to measure against (default: fitted to this
    motion, or level at ``floor``), e.g. ``Cleanup.ground`` to measure a
    cleaned motion against the floor it was cleaned on; ``meters_per_unit``:
    default the skeleton's length unit.
    """
    arrays, fitted, mpu = prepare(motion, legs=legs, up=up, floor=floor, meters_per_unit=meters_per_unit)
    ground = fitted if ground is None else ground
    return measure(arrays, ground, contacts_of(contacts, motion, arrays, ground, mpu), motion.frame_rate, mpu)


def knee_bends(arrays: LegArrays) -> np.ndarray:
    """Each leg's knee bend (legs, frames) in degrees: the angle between thigh and shin (0 straight)."""
    thigh = arrays.points[:, :, 0] - arrays.hips
    shin = arrays.points[:, :, 1] - arrays.points[:, :, 0]
    cos = np.sum(thigh * shin, -1) / (np.linalg.norm(thigh, axis=-1) * np.linalg.norm(shin, axis=-1))
    return np.degrees(np.arccos(np.clip(cos, -1, 1)))
