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
- :func:`words`, Müller, Röder and Clausen's relational features (SIGGRAPH 2005): yes/no
  facts such as "the right foot is in front of the left", "a hand is above the head"
  (RELATIONS), each with two thresholds so that a fact does not flicker at its edge, packed
  into one word per frame (:func:`mtcore.search.relations`, in C), whose runs the index holds.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from mtcore.search import Relation, relations

from ..characters.rigs import recognise, wrist
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
    ("left_wrist", ()),  # rigs.wrist: the wrist or hand joint, or the End Site of a hand-less forearm
    ("right_wrist", ()),
    ("neck", ("neck", "spine-", "head")),
    ("head", ("head", "neck-")),
)
"""Each point of the body, and the rig parts whose joint sits there (the first the rig has; of a
chain its first joint, or with "-" its last: a rig without a head joint has its neck's top); the
wrists are where :func:`motiontheater.characters.rigs.wrist` finds them."""
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
        if point.endswith("_wrist"):
            joint = wrist(motion.skeleton, point.split("_")[0])
        else:
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


def _difference(a: str, b: str = "", c: str = "", *, axis: int, off: float, on: float, **how: Any) -> Relation:
    """Point a's coordinate ``axis`` minus b's (the lower of b's and c's; nothing: 0)."""
    return Relation("difference", _AT[a], _AT[b] if b else -1, _AT[c] if c else -1, axis, off=off, on=on, **how)


def _bend(a: str, b: str, c: str, off: float, on: float) -> Relation:
    """How far the limb a-b-c is bent at b from straight, degrees."""
    return Relation("bend", _AT[a], _AT[b], _AT[c], off=off, on=on)


def _fast(a: str, off: float, on: float) -> Relation:
    """How fast point a moves, leg lengths a second."""
    return Relation("speed", _AT[a], off=off, on=on)


_X, _Y, _Z = 0, 1, 2  # the body's axes: to its left, up, forward
_HEIGHT, _SPEED, _TURNING = 0, 1, 2  # the scalars of a body, as words passes them

RELATIONS = {
    "right foot in front of the left": _difference("right_ankle", "left_ankle", axis=_Z, off=0.1, on=0.2),
    "left foot in front of the right": _difference("left_ankle", "right_ankle", axis=_Z, off=0.1, on=0.2),
    "right foot raised": _difference("right_ankle", "left_ankle", axis=_Y, off=0.1, on=0.2),
    "left foot raised": _difference("left_ankle", "right_ankle", axis=_Y, off=0.1, on=0.2),
    "right knee bent": _bend("right_hip", "right_knee", "right_ankle", 40.0, 60.0),
    "left knee bent": _bend("left_hip", "left_knee", "left_ankle", 40.0, 60.0),
    "right hand above the head": _difference("right_wrist", "head", axis=_Y, off=-0.05, on=0.05),
    "left hand above the head": _difference("left_wrist", "head", axis=_Y, off=-0.05, on=0.05),
    "right hand in front of the body": _difference("right_wrist", axis=_Z, off=0.3, on=0.45),
    "left hand in front of the body": _difference("left_wrist", axis=_Z, off=0.3, on=0.45),
    "right hand out to the side": _difference("right_wrist", "right_shoulder", axis=_X, sign=-1.0, off=0.35, on=0.5),
    "left hand out to the side": _difference("left_wrist", "left_shoulder", axis=_X, off=0.35, on=0.5),
    # the lower knee above the wrist
    "right hand below the knees": _difference(
        "right_wrist", "right_knee", "left_knee", axis=_Y, sign=-1.0, off=-0.05, on=0.05
    ),
    "left hand below the knees": _difference(
        "left_wrist", "right_knee", "left_knee", axis=_Y, sign=-1.0, off=-0.05, on=0.05
    ),
    "right elbow bent": _bend("right_shoulder", "right_elbow", "right_wrist", 50.0, 70.0),
    "left elbow bent": _bend("left_shoulder", "left_elbow", "left_wrist", 50.0, 70.0),
    "right hand moving fast": _fast("right_wrist", 1.5, 2.0),
    "left hand moving fast": _fast("left_wrist", 1.5, 2.0),
    "right foot moving fast": _fast("right_ankle", 1.5, 2.0),
    "left foot moving fast": _fast("left_ankle", 1.5, 2.0),
    "feet apart": _difference("right_ankle", "left_ankle", axis=_X, absolute=True, off=0.45, on=0.6),
    # hips lower than 0.65 leg lengths: on when the height falls below
    "hips low": Relation("scalar", _HEIGHT, sign=-1.0, off=-0.75, on=-0.65),
    "torso leaning": Relation("lean", _AT["neck"], off=30.0, on=45.0),
    "body moving over the floor": Relation("scalar", _SPEED, off=0.6, on=0.9),
    "body turning": Relation("scalar", _TURNING, absolute=True, off=60.0, on=90.0),
}
"""Müller's relational features, bit i of a frame's word being the i-th: each a measure of the
body (leg lengths, degrees, seconds) with two thresholds, off below the first and on above the
second, so that a fact holds steady at its edge."""
_TABLE = tuple(RELATIONS.values())


def words(b: Body) -> np.ndarray:
    """The relational features of each frame as one word (uint64, bit i the i-th of RELATIONS)."""
    scalars = np.stack([b.height, b.speed, b.turning], axis=1)
    return relations(b.points, scalars, b.rate, _TABLE).words


def describe(word: int) -> list[str]:
    """The relations a word holds, for a person."""
    return [name for i, name in enumerate(RELATIONS) if int(word) >> i & 1]
