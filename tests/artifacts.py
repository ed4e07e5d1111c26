"""Artifacts put into real takes at random frames and joints, for the take check's tests: what
each capture problem does to the channels, and where it was put (the truth a finding must hit).

Every injection is in physical units (degrees, metres, seconds) converted with the take's own
length unit and frame rate, and lies at least MARGIN frames inside the take, so that the
frames around it (which the fixes interpolate from) are the take's own."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

import motiontheater as mt
from motiontheater.databases.check import HUMAN_JOINTS
from motiontheater.model.rig import body_joint
from motiontheater.model.skeleton import ROTATIONS, TRANSLATIONS

KINDS = ("spike", "flip", "gap", "frozen", "teleport", "unit")
MARGIN = 8


@dataclass(frozen=True)
class Truth:
    kind: str
    joint: str | None
    first: int  # frame numbers, as the file numbers them
    last: int


def _triples(take: mt.Motion) -> list[tuple[str, np.ndarray]]:
    """Joints with three rotation channels of a Tait-Bryan order, and their columns."""
    return [
        (take.channels[int(row[0])][0], row)
        for order, _, columns in take.skeleton.euler_groups()
        if order[0] != order[2]
        for row in columns
    ]


def _moving(take: mt.Motion, columns: np.ndarray, rows: slice, degrees: float) -> bool:
    """Whether the channels move (more than 2 degrees, unwrapped) over the rows."""
    block = np.unwrap(take.values[rows][:, columns], axis=0, period=360.0 / degrees) * degrees
    return bool(np.ptp(block, axis=0).max() > 2.0)


def inject(take: mt.Motion, kind: str, rng: np.random.Generator) -> tuple[mt.Motion, Truth] | None:
    """The take with one artifact of ``kind`` put in, and where; None where the take has no
    place for it (too short, no joint that moves there)."""
    rows = take.frames
    if rows < 2 * MARGIN + 30:
        return None
    rate, meters = take.frame_rate, take.skeleton.meters_per_unit
    degrees = 1.0 if take.skeleton.angle_unit == "deg" else 180 / np.pi
    values = take.values.copy()
    triples = _triples(take)
    root = body_joint(take)
    for _ in range(20):  # a place where the artifact shows: a joint that moves there
        if kind == "unit":
            if len(take.skeleton.joint_names) < HUMAN_JOINTS:
                return None  # no unit makes a chain of a few bones a person: the check suggests none
            factor = float(rng.choice([10.0, 0.1, 2.54, 1 / 2.54, 100.0]))
            return take.with_units(length_factor=factor), Truth("unit", None, take.first_frame, take.last_frame)
        length = {
            "spike": int(rng.integers(1, 3)),
            "flip": int(rng.integers(5, 60)),
            "teleport": int(rng.integers(1, 4)),
        }
        length["gap"] = int(rng.integers(1, max(2, round(0.2 * rate))))
        length["frozen"] = int(rng.integers(round(0.15 * rate), round(0.4 * rate)))
        n = length[kind]
        if rows - MARGIN - n <= MARGIN:
            return None
        start = int(rng.integers(MARGIN, rows - MARGIN - n))
        rows_hit = slice(start, start + n)
        if kind == "teleport":
            columns = take.columns(root, TRANSLATIONS)
            if len(columns) != 3:
                return None
            direction = rng.normal(size=3)
            direction /= np.linalg.norm(direction)
            values[rows_hit, columns] += direction * rng.uniform(0.5, 2.0) / meters
            joint = root
        elif kind == "gap":
            if not triples:
                return None
            joint, columns = triples[int(rng.integers(len(triples)))]
            values[rows_hit, take.skeleton.columns_of([joint])] = np.nan
        elif kind == "frozen":
            turning = [i for i, (_, dof) in enumerate(take.channels) if dof in ROTATIONS]
            c = int(rng.choice(turning))
            span = slice(start - 2, start + n + 2)
            if not _moving(take, np.array([c]), span, degrees) or np.ptp(values[span, c]) * degrees < 10:
                continue
            values[rows_hit, c] = values[start - 1, c]
            if (values[rows_hit] == values[start - 1]).all():
                values[rows_hit, c] = take.values[rows_hit, c]
                continue  # nothing else moves there: a held channel is a held frame
            joint = take.channels[c][0]
            return _made(
                take, values, Truth("frozen", joint, take.first_frame + start - 1, take.first_frame + start + n - 1)
            )
        else:
            if not triples:
                return None
            joint, columns = triples[int(rng.integers(len(triples)))]
            if not _moving(take, columns, slice(start - 2, start + n + 2), degrees):
                continue
            if kind == "spike":
                span = slice(start - 2, start + n + 2)
                c = int(rng.choice([c for c in columns if _moving(take, np.array([c]), span, degrees)]))
                values[rows_hit, c] += rng.choice([-1, 1]) * rng.uniform(20, 60) / degrees
            else:
                half = 180.0 / degrees
                a, b, c = (values[rows_hit, col] for col in columns)
                flipped = np.stack([a + half, half - b, c + half], axis=1)
                values[rows_hit, columns[0]] = (flipped[:, 0] + half) % (2 * half) - half
                values[rows_hit, columns[1]] = (flipped[:, 1] + half) % (2 * half) - half
                values[rows_hit, columns[2]] = (flipped[:, 2] + half) % (2 * half) - half
        truth = Truth(kind, joint, take.first_frame + start, take.first_frame + start + n - 1)
        return _made(take, values, truth)
    return None


def _made(take: mt.Motion, values: np.ndarray, truth: Truth) -> tuple[mt.Motion, Truth]:
    values.flags.writeable = False
    return take.replace(values=values, origin=None), truth


def hits(finding, truth: Truth, slack: int = 2) -> bool:
    """Whether a finding is the injected artifact: its kind, its joint, frames that overlap."""
    if finding.kind != truth.kind:
        return False
    if truth.joint is not None and truth.joint not in finding.joints:
        return False
    return finding.first <= truth.last + slack and truth.first <= finding.last + slack
