"""The rig model: what of a take's channels is motion, and which joint carries the body.

Game-studio BVH rigs put six channels on every joint and a static joint above the hips: a
joint's position channels there only repeat its OFFSET, and the root stands still while the
hips travel.  Steps that reason about the body (legs, footplants, the cleanup, retargeting,
the viewer's camera) work on a :class:`BodyView` of such a take: the body joint as the root
(the static joints above it folded into its channels), and the position channels that hold
only an offset folded into the offsets.  ``BodyView.restore`` puts a result back into the
take's own layout, every channel the step did not change exactly as found.

- The **body** is the joint the caller chose (:func:`choose_body`, ``--body``); else the first joint (in the file's order) whose position channels move; where
  none does, the hips by name (the root's name first, else the one nearest the root: SMPL-named
  rigs hold a ``Pelvis_L_Hip`` below their ``Pelvis``); else the root.
- A position channel **holds an offset** where it is constant over the take to a millionth of
  the figure's size (1.7 µm for a person: below any file's printed precision).
"""

from __future__ import annotations

import re
import weakref
from dataclasses import dataclass, replace

import numpy as np

from mtcore.rotations import euler_to_matrices, matrices_to_euler, unroll_euler

from .errors import UnknownNameError
from .motion import Motion
from .skeleton import ROTATIONS, TRANSLATIONS, Bone, Root, Skeleton, canonical_hierarchy
from .units import size_up_poses

_HIPS = re.compile(r"^(?:.*[:_| ])?(?:hips?|pelvis)$", re.IGNORECASE)  # mixamorig:Hips, Bip01 Pelvis
STILL = 1e-6  # of the figure's size: a channel whose spread is below it holds an offset
STANDING = 0.25  # of a pose's largest extent: the least height of a standing figure's root


@dataclass(frozen=True)
class BodyView:
    """A take seen from its body: see the module docstring.

    ``motion`` is the view; ``original`` the take; ``body`` the body joint's name in the take
    (``"root"`` when the root carries the body); ``columns[i]`` the take's column that the
    view's column ``i`` holds; ``above`` the static transform of the joints above the body
    (4 x 4, world from the body's parent), None where it is the identity.
    """

    motion: Motion
    original: Motion
    body: str
    columns: np.ndarray
    above: np.ndarray | None

    @property
    def identity(self) -> bool:
        """Whether the view is the take itself (nothing static above the body, nothing folded)."""
        return self.motion is self.original

    @property
    def still_above(self) -> list[str]:
        """The take's joints above the body, root first ("root" for the root): they stand still."""
        return [] if self.body == "root" else _chain_above(self.original.skeleton, self.body)

    def unturned(self) -> Motion:
        """The view with the static joints' turn taken out (their shift kept): the body as it moves
        in the axes the static joints stand it in.  A z-up export whose static root turns a y-up
        take is y-up here, as its rest pose is: what retargeting compares rest poses by."""
        if self.above is None or np.allclose(self.above[:3, :3], np.eye(3), rtol=0, atol=1e-12):
            return self.motion
        back = np.eye(4)
        back[:3, :3] = self.above[:3, :3].T
        order = self.motion.skeleton.root.order
        values = np.array(self.motion.values)
        values[:, : len(order)] = _through(values[:, : len(order)], order, back)
        values.flags.writeable = False
        return self.motion.replace(values=values)

    def restore(self, result: Motion) -> Motion:
        """A result computed on the view, in the take's layout: the view's channels put back
        where they came from (the body's through the static joints above it), every other channel
        as the take has it (for a result of other frames, as the take's first frame has it)."""
        if self.identity:
            return result
        if result.frames == self.original.frames:
            values = self.original.values.copy()
        else:  # cut, spliced or resampled: what the view leaves out stands still, as in frame 1
            values = np.repeat(self.original.values[:1], result.frames, axis=0)
        view = np.array(result.values, dtype=np.float64)
        if self.above is not None:
            view = view.copy()
            root_columns = len(self.motion.skeleton.root.order)
            view[:, :root_columns] = _through(
                view[:, :root_columns], self.motion.skeleton.root.order, np.linalg.inv(self.above)
            )
        values[:, self.columns] = view
        values.flags.writeable = False
        return self.original.replace(values=values, frame_rate=result.frame_rate, first_frame=result.first_frame)


def body_joint(motion: Motion, still: set[int] | None = None) -> str:
    """The joint that carries the body: the first whose position channels move, else the hips by
    name (the root's, else the one nearest the root), else the root (``"root"``).  ``still``: the take's still columns, where known."""
    skeleton = motion.skeleton
    if skeleton.body is not None:
        return "root" if skeleton.is_root(skeleton.body) else skeleton.body
    if still is None:  # of the position channels: the others do not say
        still = _still_columns(motion, skeleton.derived("position columns", lambda: _position_columns(motion)))
    for joint in skeleton.joint_names:
        columns = [c for c, d in zip(motion.columns(joint), skeleton.dofs(joint)) if d in TRANSLATIONS]
        if any(c not in still for c in columns):
            return joint
    if _HIPS.match(skeleton.root.name):
        return "root"
    named = [b.name for b in skeleton.bones if _HIPS.match(b.name) and not b.end_site]
    return min(named, key=lambda name: len(_chain_above(skeleton, name))) if named else "root"


def body_view(motion: Motion) -> BodyView:
    """The take seen from its body (see the module docstring); the take itself where its root
    carries the body and no position channel holds only an offset.  ASF skeletons are their own
    view (their translation dofs add to a bone's vector, and only the root moves in CMU/HDM05)."""
    identity = BodyView(motion, motion, "root", np.arange(motion.values.shape[1]), None)
    skeleton = motion.skeleton
    if skeleton.convention != "bvh" or not motion.frames:
        return identity
    still = _still_columns(motion)
    body = body_joint(motion, still)  # one pass over the values for both
    chain = _chain_above(skeleton, body)
    if moving := [joint for joint in chain if any(c not in still for c in motion.columns(joint))]:
        if skeleton.body is not None:
            names = ", ".join(skeleton.root.name if j == "root" else j for j in moving)
            raise ValueError(
                f"the body joint '{skeleton.body}' chosen has joints above it that move ({names}): choose "
                "one of them or a joint above them, or let the body be found"
            )
        body, chain = "root", []  # a moving joint above the body: the take is seen from its root
    folded = {
        j
        for j in skeleton.bone_names
        if j != body
        and (dofs := skeleton.dofs(j))
        and any(d in TRANSLATIONS for d in dofs)
        and all(c in still for c, d in zip(motion.columns(j), dofs) if d in TRANSLATIONS)
    }
    if body == "root" and not folded:
        return identity
    above = _static_transform(motion, chain) if chain else None
    if above is not None and np.allclose(above, np.eye(4), rtol=0, atol=1e-12):
        above = None
    turns = [d for d in skeleton.dofs(body) if d in ROTATIONS]
    if above is not None and (len(turns) != 3 or not all(d in skeleton.dofs(body) for d in TRANSLATIONS)):
        body, chain, above = "root", [], None  # the body cannot carry the static joints' turn: seen from the root
        if not folded:
            return identity
    keep = _below(skeleton, body)
    first = motion.values[0]
    bones: list[Bone] = []
    pairs: list[tuple[str, tuple[str, ...]]] = []
    columns = list(motion.columns(body))
    for bone in skeleton.bones:
        if bone.name not in keep or bone.name == body:
            continue
        dofs, direction = bone.dofs, bone.direction
        if bone.name in folded:
            at = dict(zip(dofs, motion.columns(bone.name)))
            x, y, z = (float(first[at[d]]) if d in at else v for d, v in zip(TRANSLATIONS, direction))
            direction = (x, y, z)
            dofs = tuple(d for d in dofs if d not in TRANSLATIONS)
        bones.append(replace(bone, direction=direction, length=float(np.linalg.norm(direction)), dofs=dofs))
        columns += [c for c, d in zip(motion.columns(bone.name), bone.dofs) if d in dofs]
        parent = skeleton.parent(bone.name)
        pairs.append(("root" if parent == body else parent, (bone.name,)))
    body_dofs = skeleton.dofs(body)
    position = skeleton.root.position if body == "root" else skeleton.bone(body).direction
    root = Root(order=body_dofs, position=position, name=skeleton.root.name if body == "root" else body)
    values = motion.values[:, columns]
    if above is not None:
        values = values.copy()
        values[:, : len(body_dofs)] = _through(values[:, : len(body_dofs)], body_dofs, above)
    values = np.ascontiguousarray(values)
    values.flags.writeable = False
    view_skeleton = Skeleton(
        bones=tuple(bones),
        hierarchy=canonical_hierarchy(tuple(bones), pairs),
        root=root,
        name=skeleton.name,
        units=skeleton.units,
        convention="bvh",
        length_choice=skeleton.length_choice,
    )
    view = Motion(view_skeleton, values, frame_rate=motion.frame_rate, first_frame=motion.first_frame)
    return BodyView(view, motion, body, np.array(columns, dtype=np.intp), above)


def choose_body(motion: Motion, joint: str) -> Motion:
    """The take with ``joint`` (a joint's name, the root's included) as the joint that carries its
    body, in place of the one :func:`body_joint` finds; UnknownNameError naming the joints there are."""
    skeleton = motion.skeleton
    names = {skeleton.root.name: "root", "root": "root", **{b.name: b.name for b in skeleton.bones if not b.end_site}}
    if joint not in names:
        shown = ", ".join(n for n in names if n != "root" or skeleton.root.name == "root")
        raise UnknownNameError(f"no joint '{joint}' to carry the body; the take's joints are {shown}")
    return motion.replace(skeleton=replace(skeleton, body=joint))


def rest_view(skeleton: Skeleton) -> BodyView:
    """A skeleton seen from its body as :func:`body_view` sees a take of it standing still at rest
    (every rotation channel zero, every position channel below the root holding its OFFSET): the
    hips by name carry the body, every other joint's position channels are offsets.  What a plan
    made for a skeleton without its frames (a retarget target) works on."""
    return body_view(Motion(skeleton, rest_values(skeleton)))


def rest_values(skeleton: Skeleton, frames: int = 1) -> np.ndarray:
    """(frames, channels) of the skeleton at rest: a BVH joint's position channels below the root
    hold its OFFSET (they replace it); every other channel (rotations, ASF translations and
    stretch, the root's position) is zero."""
    values = np.zeros((frames, len(skeleton.channels)))
    if skeleton.convention == "bvh":
        for column, (joint, dof) in enumerate(skeleton.channels):
            if dof in TRANSLATIONS and not skeleton.is_root(joint):
                values[:, column] = skeleton.bone(joint).direction[TRANSLATIONS.index(dof)]
    return values


POSES = 32  # frames, spread over a take, whose poses tell its up axis: quick on hours of frames


def body_reason(view: BodyView) -> str:
    """Why the view's joint carries the body, in words (what ``info`` says)."""
    motion, skeleton, above = view.original, view.original.skeleton, view.still_above
    if skeleton.convention != "bvh":
        why = "the root of an ASF skeleton carries the body"
    elif view.body == "root" and not above:
        why = "the root carries the body"
    elif any(np.ptp(motion.values[:, c]) > 0 for c in motion.columns(view.body) if motion.frames):
        why = "the first joint in the file whose position channels move"
    else:
        why = "named as the hips; no position channel moves"
    if above:
        why += (
            f"; the joints above it stand still ({', '.join(skeleton.root.name if j == 'root' else j for j in above)})"
        )
    return why


_SAMPLED: weakref.WeakKeyDictionary[Motion, Motion] = weakref.WeakKeyDictionary()


def sampled_view(motion: Motion) -> Motion:
    """Up to :data:`POSES` frames spread over the take, seen from its body (the view of those
    frames alone, which on an hour of frames is what keeps the up axis and the standing frame
    quick to find).  Made once per take (a Motion does not change): the up axis, the facing and
    the standing frame all start from it."""
    view = _SAMPLED.get(motion)
    if view is None:
        view = _SAMPLED[motion] = body_view(motion.replace(values=motion.values[_sampled(motion.frames)])).motion
    return view


def sampled_poses(motion: Motion) -> np.ndarray:
    """World positions (poses, points, 3) of :func:`sampled_view` (the static joints' turn folded in)."""
    return sampled_view(motion).positions()


def _sampled(frames: int) -> np.ndarray:
    return np.unique(np.linspace(0, frames - 1, min(POSES, frames)).round().astype(int))


def pose_up(motion: Motion) -> str:
    """ "y" or "z": the axis along which most of the take's poses stand taller (the rest pose's
    where it has no frames); ASF/AMC is y-up by Acclaim's convention.  Where legs are known by
    name, :func:`motiontheater.feet.upright.take_up` tells the sign as well."""
    if motion.skeleton.convention != "bvh":
        return "y"
    if not motion.frames:
        return motion.skeleton.sizing().up
    return size_up_poses(sampled_poses(motion)).up


def standing_frame(motion: Motion) -> tuple[float, ...] | None:
    """The channels of the frame, of the :func:`sampled_poses`, whose figure stands tallest
    (:func:`standing_height`, the body as the root), or None where none stands."""
    if not motion.frames:
        return None
    chosen = _sampled(motion.frames)
    heights = [standing_height(pose) for pose in sampled_poses(motion)]
    best = int(np.argmax(heights))
    return tuple(float(v) for v in motion.values[chosen[best]]) if heights[best] > STANDING else None


def standing_height(points: np.ndarray) -> float:
    """How high the root (point 0) of a pose (points, 3) stands above its lowest point, along y or
    z (whichever the pose spans more), as a fraction of the pose's largest extent (NaN: 0)."""
    points = np.asarray(points, dtype=float)
    finite = points[np.isfinite(points).all(axis=1)]
    if len(points) < 2 or not np.isfinite(points[0]).all() or len(finite) < 2:
        return 0.0
    spans = np.ptp(finite, axis=0)
    up = 2 if spans[2] > spans[1] else 1
    return float((points[0, up] - finite[:, up].min()) / spans.max()) if spans.max() > 0 else 0.0


def _position_columns(motion: Motion) -> list[int]:
    skeleton = motion.skeleton
    return [
        c
        for joint in skeleton.joint_names
        for c, d in zip(motion.columns(joint), skeleton.dofs(joint))
        if d in TRANSLATIONS
    ]


def _still_columns(motion: Motion, columns: list[int] | None = None) -> set[int]:
    """The columns (of ``columns``, default all) that do not move over the take (to STILL of the
    figure's size, NaN-free)."""
    chosen = np.arange(motion.values.shape[1]) if columns is None else np.asarray(columns, dtype=np.intp)
    values = motion.values if columns is None else motion.values[:, chosen]
    if not len(values):
        return set(chosen.tolist())
    size = motion.skeleton.derived("figure size", lambda: _figure_size(motion.skeleton))
    with np.errstate(invalid="ignore"):  # a column held at an infinity spans NaN: not told still
        spread = np.ptp(values, axis=0)
    return set(chosen[spread <= STILL * max(size, 1.0)].tolist())


def _figure_size(skeleton: Skeleton) -> float:
    """The largest extent of the rest pose along an axis, in file units (0 for one joint)."""
    rest = skeleton.rest_positions()
    with np.errstate(invalid="ignore"):
        return float(np.nanmax(np.ptp(rest, axis=0))) if len(rest) > 1 else 0.0


def _chain_above(skeleton: Skeleton, joint: str) -> list[str]:
    """The joints from the root down to ``joint``'s parent (empty for the root)."""
    chain: list[str] = []
    while joint != "root":
        joint = skeleton.parent(joint)
        chain.append(joint)
    return chain[::-1]


def _below(skeleton: Skeleton, joint: str) -> set[str]:
    found, todo = set(), [joint]
    while todo:
        name = todo.pop()
        found.add(name)
        todo.extend(skeleton.children(name))
    return found


def _local(dofs: tuple[str, ...], values: np.ndarray, offset) -> np.ndarray:
    """(frames, 4, 4): a BVH joint's transform in its parent's frame, from its channels (position
    channels replacing the offset; rotations R1 R2 R3 in the listed order)."""
    frames = len(values)
    transform = np.tile(np.eye(4), (frames, 1, 1))
    transform[:, :3, 3] = offset
    for i, d in enumerate(dofs):
        if d in TRANSLATIONS:
            transform[:, TRANSLATIONS.index(d), 3] = values[:, i]
    turning = [i for i, d in enumerate(dofs) if d in ROTATIONS]
    if turning:
        order = "".join(dofs[i][1] for i in turning)
        transform[:, :3, :3] = euler_to_matrices(values[:, turning], order, extrinsic=False, degrees=True)
    return transform


def _static_transform(motion: Motion, chain: list[str]) -> np.ndarray:
    """The world transform of the last joint of ``chain`` (whose channels stand still), frame 1."""
    skeleton = motion.skeleton
    world = np.eye(4)
    for joint in chain:
        offset = skeleton.root.position if joint == "root" else skeleton.bone(joint).direction
        world = world @ _local(skeleton.dofs(joint), motion.values[:1, motion.columns(joint)], offset)[0]
    return world


def _through(channels: np.ndarray, dofs: tuple[str, ...], transform: np.ndarray) -> np.ndarray:
    """A joint's channels (frames, dofs: xyz positions and rotations) as they are in the frame
    ``transform`` maps its parent's into."""
    local = _local(dofs, channels, (0.0, 0.0, 0.0))
    moved = transform @ local
    out = channels.copy()
    for i, d in enumerate(dofs):
        if d in TRANSLATIONS:
            out[:, i] = moved[:, TRANSLATIONS.index(d), 3]
    turning = [i for i, d in enumerate(dofs) if d in ROTATIONS]
    if turning and not np.array_equal(transform[:3, :3], np.eye(3)):  # a shift alone keeps the angles as found
        order = "".join(dofs[i][1] for i in turning)
        angles = matrices_to_euler(moved[:, :3, :3], order, extrinsic=False, degrees=True)
        if len(turning) == 3:  # continuous over frames, not wrapped into (-180, 180]
            angles = unroll_euler(angles, order, degrees=True)
        # whole turns that bring the first frame nearest the channels' own: a filter sees no jump
        angles += 360.0 * np.round((channels[:1, turning] - angles[:1]) / 360.0)
        out[:, turning] = angles
    return out
