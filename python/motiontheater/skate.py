"""Footskate metrics of a take: how much its planted feet slide, sink and float, and how often they skate.

Per foot (its heel and ball; heights are above where each point rests, see
:mod:`motiontheater.legs`):

- ``plants``: footplants of the heel and of the ball;
- ``sliding_mean_mm``, ``sliding_max_mm``: over every planted frame, the
  horizontal distance of the planted point from where it was at the plant's
  first frame;
- ``skating_ratio``: the share of frame steps t -> t+1 (frames - 1 of them) in
  which the foot skates, as motion-generation papers count it: a point within
  5 cm of the floor at t and t+1 whose horizontal speed and that speed's
  moving average over 5 frames at 20 Hz (0.25 s, rescaled to the take's
  frame rate) both exceed 0.5 m/s;
- ``penetration_mm``: the deepest any of its heel, ball and toe tip goes below
  where it rests, over all frames;
- ``float_mm``: the mean height of planted points over their plants.
"""

from __future__ import annotations

import json
from dataclasses import dataclass

import numpy as np

from .contacts import PLANT_POINTS, Contacts, runs
from .footskate import _contacts, prepare
from .legs import Ground, LegArrays, Legs
from .motion import Motion

SKATE_HEIGHT = 0.05  # m
SKATE_SPEED = 0.5  # m/s
SKATE_WINDOW = 5 / 20.0  # s: 5 frames at 20 Hz


@dataclass(frozen=True)
class FootMetrics:
    foot: str
    plants: dict[str, int]
    sliding_mean_mm: float
    sliding_max_mm: float
    skating_ratio: float
    penetration_mm: float
    float_mm: float


@dataclass(frozen=True)
class SkateReport:
    """Metrics per foot (see the module docstring), the frames and the take's frame rate."""

    feet: tuple[FootMetrics, ...]
    frames: int
    frame_rate: float

    def as_dict(self) -> dict:
        return {
            "frames": self.frames,
            "frame_rate": self.frame_rate,
            "feet": [
                {
                    "foot": f.foot,
                    "plants": f.plants,
                    "sliding_mean_mm": f.sliding_mean_mm,
                    "sliding_max_mm": f.sliding_max_mm,
                    "skating_ratio": f.skating_ratio,
                    "penetration_mm": f.penetration_mm,
                    "float_mm": f.float_mm,
                }
                for f in self.feet
            ],
        }

    def to_json(self) -> str:
        return json.dumps(self.as_dict(), indent=2)

    def text(self) -> str:
        lines = [
            "| foot | plants (heel, ball) | sliding mean mm | sliding max mm | skating % | penetration mm | float mm |",
            "|---|---|---:|---:|---:|---:|---:|",
        ]
        for f in self.feet:
            lines.append(
                f"| {f.foot} | {f.plants['heel']}, {f.plants['ball']} | {f.sliding_mean_mm:.2f} | "
                f"{f.sliding_max_mm:.2f} | {100 * f.skating_ratio:.2f} | {f.penetration_mm:.2f} | {f.float_mm:.2f} |"
            )
        return "\n".join(lines)


def _horizontal(p: np.ndarray, up: np.ndarray) -> np.ndarray:
    return p - (p @ up)[..., None] * up


def moving_average(x: np.ndarray, width: int) -> np.ndarray:
    """Centred mean over ``width`` samples (odd), the window cut at the ends."""
    if width <= 1 or len(x) == 0:
        return x.astype(float)
    half = width // 2
    c = np.r_[0.0, np.cumsum(x)]
    idx = np.arange(len(x))
    lo, hi = np.maximum(idx - half, 0), np.minimum(idx + half + 1, len(x))
    return (c[hi] - c[lo]) / (hi - lo)


def measure(arrays: LegArrays, ground: Ground, contacts: Contacts, frame_rate: float, mpu: float) -> SkateReport:
    """The metrics of leg arrays on a ground with a contacts table."""
    legs = arrays.legs
    up = np.asarray(ground.up)
    masks = contacts.masks(legs)
    heights = ground.heights(arrays.points)  # (legs, frames, 3): heel, ball, tip
    frames = arrays.points.shape[1]
    window = max(1, int(round(SKATE_WINDOW * frame_rate)) // 2 * 2 + 1)
    feet = []
    for i, foot in enumerate(legs.feet):
        slides = []
        for k, column in enumerate((3, 2)):
            starts, ends = runs(masks[i, :, k])
            p = _horizontal(arrays.points[i, :, column], up)
            for s, e in zip(starts, ends):
                slides.append(np.linalg.norm(p[s:e] - p[s], axis=-1))
        slide = np.concatenate(slides) * mpu * 1000 if slides else np.zeros(0)
        skating = np.zeros(max(frames - 1, 0), bool)
        for k, column in enumerate((3, 2)):
            if frames < 2:
                break
            p = _horizontal(arrays.points[i, :, column], up)
            speed = np.linalg.norm(np.diff(p, axis=0), axis=-1) * frame_rate * mpu
            low = heights[i, :, k] * mpu < SKATE_HEIGHT
            skating |= low[:-1] & low[1:] & (speed > SKATE_SPEED) & (moving_average(speed, window) > SKATE_SPEED)
        valid = [k for k in range(3) if k < 2 or legs.points[i, 4] >= 0]
        depth = -np.nanmin(heights[i][:, valid]) if frames else 0.0
        planted_heights = heights[i, :, :2][masks[i]]
        feet.append(
            FootMetrics(
                foot=foot,
                plants={point: len(contacts.of(foot, point)) for point in PLANT_POINTS},
                sliding_mean_mm=float(slide.mean()) if len(slide) else 0.0,
                sliding_max_mm=float(slide.max()) if len(slide) else 0.0,
                skating_ratio=float(skating.sum() / (frames - 1)) if frames > 1 else 0.0,
                penetration_mm=float(max(depth, 0.0) * mpu * 1000),
                float_mm=float(np.mean(np.maximum(planted_heights, 0)) * mpu * 1000) if len(planted_heights) else 0.0,
            )
        )
    return SkateReport(tuple(feet), frames, frame_rate)


def skate_metrics(
    motion: Motion,
    contacts=None,
    *,
    legs=None,
    up: str | None = None,
    floor: float | None = None,
    ground: Ground | None = None,
    meters_per_unit: float | None = None,
) -> SkateReport:
    """Footskate metrics of a motion (see the module docstring).  ``contacts``: a table or its
    CSV (default: detected on this motion); ``ground``: the floor to measure against (default:
    fitted to this motion, or level at ``floor``); the other options as for cleanup."""
    found, arrays, fitted, mpu = prepare(motion, legs=legs, up=up, floor=floor, meters_per_unit=meters_per_unit)
    if ground is not None:
        fitted = ground
    table = _contacts(contacts, motion, arrays, fitted, mpu, _default_thresholds())
    del found
    return measure(arrays, fitted, table, motion.frame_rate, mpu)


def _default_thresholds():
    from .contacts import Thresholds

    return Thresholds()


def knee_angles(arrays: LegArrays) -> np.ndarray:
    """Each leg's knee bend (legs, frames) in degrees: the angle between thigh and shin."""
    thigh = arrays.points[:, :, 0] - arrays.hips
    shin = arrays.points[:, :, 1] - arrays.points[:, :, 0]
    cos = np.sum(thigh * shin, -1) / (np.linalg.norm(thigh, axis=-1) * np.linalg.norm(shin, axis=-1))
    return np.degrees(np.arccos(np.clip(cos, -1, 1)))


__all__ = ["FootMetrics", "SkateReport", "knee_angles", "measure", "skate_metrics", "Legs"]
