"""What search by example compares: a take's body, frame by frame, independent of its rig.

Seventeen points of the body (hips, hip joints, knees, ankles, balls, shoulders, elbows, wrists,
neck and head) are found through the rig tables (:mod:`motiontheater.characters.rigs`: CMU and
HDM05 ASF names, the CMU BVH conversion, HumanIK names as Mixamo and most exporters write them),
placed by forward kinematics in metres, stood up along the take's up axis, and seen from the
body: from the hips, facing where the hips face, divided by the length of the skeleton's own
leg, so that a child's squat and a giant's are alike, in any unit and up axis.

Two things are kept per frame, at FEATURE_RATE:

- :func:`pose_features`, real numbers: the points in the body's frame, the hips' height above
  the floor and their speed over it; what dynamic time warping ranks by;
- :func:`relations`, Müller, Röder and Clausen's relational features (SIGGRAPH 2005): yes/no
  facts such as "the right foot is in front of the left", "a hand is above the head", each with
  two thresholds (hysteresis, :func:`mtcore.search.hysteresis`) so that a fact does not flicker
  at its edge; packed into one word per frame, whose runs the index holds.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mtcore.search import hysteresis, pack_bits

from ..characters.rigs import recognise
from ..feet.upright import take_up
from ..model.motion import Motion
from ..model.rig import body_joint

FEATURE_RATE = 10.0
"""Hz: the rate features are kept at (Müller et al. use 10 Hz: motion classes differ in
seconds, not in hundredths)."""

POINTS = (
    ("hips", ()),  # the joint that carries the body (a static root above it is no body)
    ("left_hip", ("left_thigh",)),
    ("right_hip", ("right_thigh",)),
    ("left_knee", ("left_shin",)),
    ("right_knee", ("right_shin",)),
    ("left_ankle", ("left_foot",)),
    ("right_ankle", ("right_foot",)),
    ("left_ball", ("left_toes", "left_foot")),
    ("right_ball", ("right_toes", "right_foot")),
    ("left_shoulder", ("left_upper_arm",)),
    ("right_shoulder", ("right_upper_arm",)),
    ("left_elbow", ("left_forearm",)),
    ("right_elbow", ("right_forearm",)),
    ("left_wrist", ("left_wrist", "left_hand")),
    ("right_wrist", ("right_wrist", "right_hand")),
    ("neck", ("neck", "spine-", "head")),
    ("head", ("head", "neck-")),
)
"""Each point of the body, and the rig parts whose joint sits there (the first the rig has; of a
chain its first joint, or with "-" its last: a rig without a head joint has its neck's top)."""
_AT = {name: i for i, (name, _) in enumerate(POINTS)}
SPEED_WEIGHT = 0.5
"""How much the hips' speed over the floor (leg lengths per second) counts against the pose."""


@dataclass(frozen=True)
class Body:
    """A take's body points (frames, points, 3) in the body's frame, in leg lengths: x to the
    body's left, y up, z forward; ``height`` (frames,) the hips above the floor and ``speed``
    (frames,) the hips' speed over it, in leg lengths (per second), ``turning`` (frames,) how
    fast the hips turn about up, degrees per second; at ``rate`` Hz, the frame at row i being
    the take's frame ``frames[i]``; ``place`` (frames, 2) where the hips stand on the floor
    (world x and z, leg lengths) and ``facing`` (frames, 2) the unit vector they face, in x, z."""

    points: np.ndarray
    height: np.ndarray
    speed: np.ndarray
    turning: np.ndarray
    rate: float
    frames: np.ndarray
    place: np.ndarray
    facing: np.ndarray

    def at(self, name: str) -> np.ndarray:
        """The point ``name`` (one of POINTS) over the frames, (frames, 3)."""
        return self.points[:, _AT[name]]


def body(motion: Motion, rate: float = FEATURE_RATE, *, frame: int | None = None) -> Body:
    """The take's body at ``rate`` Hz (frames nearest each tick; the take's own rate if lower),
    the ticks from the first frame, or placed so that one falls on ``frame`` (a frame number).
    ValueError where the skeleton has no hips, legs, arms and head that the rig tables know."""
    joints = _joints(motion)
    step = max(motion.frame_rate / rate, 1.0)
    anchor = 0 if frame is None else frame - motion.first_frame
    start = anchor - step * np.floor(anchor / step)
    ticks = np.arange(start, motion.frames, step)
    rows = np.unique(np.round(ticks).astype(int).clip(0, max(motion.frames - 1, 0)))
    sampled = motion.replace(values=motion.values[rows]) if motion.frames else motion
    start = motion.skeleton.convention != "bvh"  # an ASF bone turns at its start, a BVH joint at itself
    world = sampled.positions(start=start, meters=True)[:, joints]
    world = _filled(world @ take_up(motion).turn.T)  # y up
    rest = motion.skeleton.rest_positions(start=start)[joints] * motion.skeleton.meters_per_unit
    leg = float(
        np.mean(
            [
                np.linalg.norm(rest[_AT[f"{s}_hip"]] - rest[_AT[f"{s}_knee"]])
                + np.linalg.norm(rest[_AT[f"{s}_knee"]] - rest[_AT[f"{s}_ankle"]])
                for s in ("left", "right")
            ]
        )
    )
    if not leg > 0:
        raise ValueError("the skeleton's legs have no length: its body cannot be measured")
    hips = world[:, _AT["hips"]]
    left = world[:, _AT["left_hip"]] - world[:, _AT["right_hip"]]
    left[:, 1] = 0.0
    norm = np.linalg.norm(left, axis=1, keepdims=True)
    left = np.where(norm > 1e-9, left / np.where(norm > 1e-9, norm, 1.0), [1.0, 0.0, 0.0])
    up = np.broadcast_to([0.0, 1.0, 0.0], left.shape)
    forward = np.cross(left, up)
    basis = np.stack([left, up, forward], axis=1)  # (frames, 3 axes, 3)
    points = np.einsum("fad,fpd->fpa", basis, world - hips[:, None]) / leg
    feet = world[:, [_AT[p] for p in ("left_ankle", "right_ankle", "left_ball", "right_ball")], 1]
    floor = float(np.percentile(feet.min(axis=1), 5)) if len(feet) else 0.0
    tick = step / motion.frame_rate
    ground = hips[:, [0, 2]]
    speed = np.zeros(len(rows))
    turning = np.zeros(len(rows))
    if len(rows) > 1:
        speed = np.gradient(ground, axis=0)
        speed = np.linalg.norm(speed, axis=1) / tick / leg
        heading = np.unwrap(np.arctan2(forward[:, 0], forward[:, 2]))
        turning = np.degrees(np.gradient(heading)) / tick
    return Body(
        points, (hips[:, 1] - floor) / leg, speed, turning, 1 / tick, rows + motion.first_frame,
        hips[:, [0, 2]] / leg, forward[:, [0, 2]],
    )  # fmt: skip


def _joints(motion: Motion) -> list[int]:
    parts = recognise(motion.skeleton).parts
    names = motion.skeleton.point_names  # the rig tables name the root as the file does
    out, missing = [motion.skeleton.joint_names.index(body_joint(motion))], []  # the hips: the body's joint
    for point, tried in POINTS[1:]:
        joint = next(
            (parts[p.rstrip("-")][-1 if p.endswith("-") else 0] for p in tried if p.rstrip("-") in parts), None
        )
        if joint is None:
            missing.append(point)
        else:
            out.append(names.index(joint))
    if missing:
        raise ValueError(
            f"no {', '.join(missing)} found by name in skeleton '{motion.skeleton.name or '(unnamed)'}': "
            "search compares bodies (hips, legs, arms, head) and its rig is not one the rig tables know"
        )
    return out


def _filled(world: np.ndarray) -> np.ndarray:
    """Positions with frames of NaN (gaps) filled linearly from the frames around them."""
    bad = ~np.isfinite(world).all(axis=(1, 2))
    if not bad.any():
        return world
    if bad.all():
        raise ValueError("every frame misses values (NaN): there is no body to compare")
    good = np.flatnonzero(~bad)
    out = world.copy()
    flat = out.reshape(len(out), -1)
    for c in range(flat.shape[1]):
        flat[bad, c] = np.interp(np.flatnonzero(bad), good, flat[good, c])
    return out


def pose_features(b: Body) -> np.ndarray:
    """(frames, dims): every point but the hips in the body's frame, the hips' height and their
    speed over the floor (weighted by SPEED_WEIGHT)."""
    return np.hstack([b.points[:, 1:].reshape(len(b.points), -1), b.height[:, None], SPEED_WEIGHT * b.speed[:, None]])


FUTURE = (0.3, 0.7, 1.0)
"""Seconds ahead at which a frame's future path is compared (motion matching's trajectory)."""
MOVE_WEIGHTS = {"feet": 1.0, "feet speed": 0.1, "hips speed": 0.2, "path": 0.5, "facing": 0.5}
"""How much each part of a frame's move counts (positions in leg lengths, speeds in leg lengths
per second, facing as unit vectors), as motion matching weights them."""


def moves(b: Body) -> np.ndarray:
    """(frames, 27) what motion matching compares at each frame, in the hips' frame at that frame:
    the ankles where they are and how fast they move (12), the hips' velocity (3), and the path
    ahead: where the hips will stand and face after each of FUTURE (12; the take's last frame
    where it ends sooner), each part weighted by MOVE_WEIGHTS."""
    n = len(b.frames)
    ankles = np.hstack([b.at("left_ankle"), b.at("right_ankle")])
    velocity = np.gradient(ankles, axis=0) * b.rate if n > 1 else np.zeros_like(ankles)
    side = np.stack([b.facing[:, 1], -b.facing[:, 0]], axis=1)  # the body's left, (x, z)

    def local(v: np.ndarray) -> np.ndarray:  # world (x, z) vectors as (to the left, ahead) at each frame
        return np.stack([np.sum(v * side, 1), np.sum(v * b.facing, 1)], axis=1)

    hips = np.gradient(b.place, axis=0) * b.rate if n > 1 else np.zeros_like(b.place)
    path, facing = [], []
    for seconds in FUTURE:
        ahead = np.minimum(np.arange(n) + round(seconds * b.rate), n - 1)
        path.append(local(b.place[ahead] - b.place))
        facing.append(local(b.facing[ahead]))
    w = MOVE_WEIGHTS
    return np.hstack(
        [
            w["feet"] * ankles,
            w["feet speed"] * velocity,
            w["hips speed"]
            * np.hstack([local(hips), np.gradient(b.height)[:, None] * b.rate if n > 1 else np.zeros((n, 1))]),
            w["path"] * np.hstack(path),
            w["facing"] * np.hstack(facing),
        ]
    )


def _angle(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """The angle at b between b->a and b->c, in degrees (180: straight)."""
    u, v = a - b, c - b
    cos = np.sum(u * v, -1) / np.maximum(np.linalg.norm(u, axis=-1) * np.linalg.norm(v, axis=-1), 1e-12)
    return np.degrees(np.arccos(np.clip(cos, -1, 1)))


RELATIONS = (
    "right foot in front of the left",
    "left foot in front of the right",
    "right foot raised",
    "left foot raised",
    "right knee bent",
    "left knee bent",
    "right hand above the head",
    "left hand above the head",
    "right hand in front of the body",
    "left hand in front of the body",
    "right hand out to the side",
    "left hand out to the side",
    "right hand below the knees",
    "left hand below the knees",
    "right elbow bent",
    "left elbow bent",
    "right hand moving fast",
    "left hand moving fast",
    "right foot moving fast",
    "left foot moving fast",
    "feet apart",
    "hips low",
    "torso leaning",
    "body moving over the floor",
    "body turning",
)
"""The relational features, bit i of a frame's word being RELATIONS[i]."""


def relations(b: Body) -> np.ndarray:
    """(frames, len(RELATIONS)) booleans: see RELATIONS; thresholds in leg lengths, degrees and
    seconds, each a pair (off below the first, on above the second) so that facts hold steady."""
    at = b.at
    values, low, high = [], [], []

    def fact(value: np.ndarray, off: float, on: float) -> None:
        values.append(value)
        low.append(off)
        high.append(on)

    rel_speed = {}
    for name in ("right_wrist", "left_wrist", "right_ankle", "left_ankle"):
        p = at(name)
        rel_speed[name] = np.linalg.norm(np.gradient(p, axis=0), axis=1) * b.rate if len(p) > 1 else np.zeros(len(p))
    fact(at("right_ankle")[:, 2] - at("left_ankle")[:, 2], 0.1, 0.2)
    fact(at("left_ankle")[:, 2] - at("right_ankle")[:, 2], 0.1, 0.2)
    fact(at("right_ankle")[:, 1] - at("left_ankle")[:, 1], 0.1, 0.2)
    fact(at("left_ankle")[:, 1] - at("right_ankle")[:, 1], 0.1, 0.2)
    for side in ("right", "left"):
        fact(180 - _angle(at(f"{side}_hip"), at(f"{side}_knee"), at(f"{side}_ankle")), 40.0, 60.0)
    for side in ("right", "left"):
        fact(at(f"{side}_wrist")[:, 1] - at("head")[:, 1], -0.05, 0.05)
    for side in ("right", "left"):
        fact(at(f"{side}_wrist")[:, 2], 0.3, 0.45)
    for side, sign in (("right", -1.0), ("left", 1.0)):
        fact(sign * (at(f"{side}_wrist")[:, 0] - at(f"{side}_shoulder")[:, 0]), 0.35, 0.5)
    for side in ("right", "left"):
        knees = np.minimum(at("right_knee")[:, 1], at("left_knee")[:, 1])
        fact(knees - at(f"{side}_wrist")[:, 1], -0.05, 0.05)
    for side in ("right", "left"):
        fact(180 - _angle(at(f"{side}_shoulder"), at(f"{side}_elbow"), at(f"{side}_wrist")), 50.0, 70.0)
    fact(rel_speed["right_wrist"], 1.5, 2.0)
    fact(rel_speed["left_wrist"], 1.5, 2.0)
    fact(rel_speed["right_ankle"], 1.5, 2.0)
    fact(rel_speed["left_ankle"], 1.5, 2.0)
    fact(np.abs(at("right_ankle")[:, 0] - at("left_ankle")[:, 0]), 0.45, 0.6)
    fact(-b.height, -0.75, -0.65)  # hips lower than 0.65 leg lengths: on when height falls below
    torso = at("neck")
    lean = np.degrees(np.arctan2(np.linalg.norm(torso[:, [0, 2]], axis=1), torso[:, 1]))
    fact(lean, 30.0, 45.0)
    fact(b.speed, 0.6, 0.9)
    fact(np.abs(b.turning), 60.0, 90.0)
    return hysteresis(np.stack(values, axis=1), np.array(low), np.array(high))


def words(b: Body) -> np.ndarray:
    """The relational features of each frame as one word (uint64, bit i RELATIONS[i])."""
    return pack_bits(relations(b))


def describe(word: int) -> list[str]:
    """The relations a word holds, for a person."""
    return [name for i, name in enumerate(RELATIONS) if int(word) >> i & 1]
