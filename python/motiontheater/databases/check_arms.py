"""The take check's findings on the arms: elbows bent backwards.

An elbow is a hinge: the forearm turns about one axis fixed in the upper arm, and one way.  Rigs
differ in which axis that is and which way is forward, so both are the take's own: the axis
the turns from upper arm to forearm share, in the upper arm's axes, over the frames where the
elbow bends well, and the way most of them turn about it.
A frame whose forearm turns the other way about that axis, past ELBOW_BACK_DEG, is bent
backwards.  A take whose elbows never bend, or turn about no one axis (an arm estimated from
video, a rig the tables do not know), has no findings here.  They are reported, not fixed: which
way the arm should have bent is not in the take.
"""

from __future__ import annotations

import numpy as np

from mtcore.check import elbow_bends
from mtcore.kinematics import Kinematics, world_kinematics

from ..characters.rigs import recognise, wrist
from ..feet.contacts import run_peaks
from ..model.motion import Motion
from ..model.skeleton import Skeleton
from .findings import Finding

ELBOW_BACK_DEG = 20.0
"""Degrees an elbow may bend backwards (past straight; up to 10-15 degrees is human, more in
the hypermobile) before it is bent backwards; 45 is high."""
BENT_DEG = 30.0
"""Frames whose elbow bends more than this tell its axis and which way it bends."""
BENT_SECONDS = 0.25
"""The least time the elbow must bend that far for the check to know its axis."""
HINGE = 0.8
"""How nearly the turns of those frames must share one axis (the share of their unit axes'
second moment along it) for the elbow to be a hinge the check can judge."""


def arm_findings(motion: Motion, take: str, kinematics: Kinematics | None = None) -> list[Finding]:
    """The elbows of the take bent backwards past ELBOW_BACK_DEG; ``kinematics``: the take's
    forward kinematics (positions, world rotations), where the caller has them (the check holds a
    long take's frames a piece at a time: :mod:`.pieces`)."""
    skeleton = motion.skeleton
    arms, placing = skeleton.derived("check arms", lambda: _arms(skeleton))
    if not len(arms) or motion.frames < 2:
        return []
    if kinematics is None:
        kinematics = world_kinematics(motion.values, skeleton.tree, workers=1)
    names = skeleton.point_names
    out = []
    bends, judged = elbow_bends(
        kinematics.positions, kinematics.world, kinematics.rows(arms[:, 1]), placing, BENT_DEG,
        BENT_SECONDS * motion.frame_rate, HINGE,
    )  # fmt: skip
    for (_, _, elbow, _), bend, told in zip(arms, bends, judged):
        if not told:  # the take does not tell the elbow's axis (see the module docstring)
            continue
        backwards = -bend[None]
        for _, s, e, worst in run_peaks(backwards > ELBOW_BACK_DEG, backwards):
            out.append(
                Finding(
                    take, "elbow", (names[elbow],), motion.first_frame + s, motion.first_frame + e - 1,
                    "high" if worst > 45 else "medium", round(worst, 6), "deg",
                    f"{names[elbow]} bends {worst:.3g} deg backwards, past what an elbow does",
                )
            )  # fmt: skip
    return out


def turned_joints(skeleton: Skeleton) -> list[int]:
    """The joints whose world rotations :func:`arm_findings` reads from the take's kinematics: the
    joint each upper arm turns with."""
    arms, _ = skeleton.derived("check arms", lambda: _arms(skeleton))
    return arms[:, 1].tolist()


def _placing(skeleton: Skeleton, arms: np.ndarray) -> np.ndarray:
    """The joints placing each arm's shoulder, elbow and wrist (arms, 3): of an ASF bone, its
    parent's end, where it starts (as positions(start=True))."""
    placing = arms[:, [0, 2, 3]]
    return placing if skeleton.convention == "bvh" else np.maximum(skeleton.tree.parent[placing], 0)


def _arms(skeleton: Skeleton) -> tuple[np.ndarray, np.ndarray]:
    """The arms the rig tables find, (arms, 4) joints: shoulder, the upper arm's turning joint,
    elbow and wrist; and the joints placing each one's shoulder, elbow and wrist (:func:`_placing`)."""
    parts = recognise(skeleton).parts
    names = list(skeleton.point_names)
    arms = []
    for side in ("left", "right"):
        end = wrist(skeleton, side)
        if f"{side}_upper_arm" in parts and f"{side}_forearm" in parts and end:
            forearm = parts[f"{side}_forearm"][0]
            turning = skeleton.parent(forearm)  # the upper arm's last joint (a roll joint's, if any)
            if turning in names:
                arms.append((names.index(parts[f"{side}_upper_arm"][0]), names.index(turning), names.index(forearm),
                             names.index(end)))  # fmt: skip
    table = np.array(arms, dtype=np.intp).reshape(-1, 4)
    return table, _placing(skeleton, table)
