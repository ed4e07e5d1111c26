"""Motions: a skeleton's channels over frames."""

from __future__ import annotations

import warnings
from collections.abc import Callable, Iterable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from mtcore.kinematics import forward_kinematics
from mtcore.rotations import matrices_to_quaternions

from .._io import PLAIN, Origin, Source, TextStyle
from .errors import UnknownNameError
from .registry import is_step, lookup
from .skeleton import ROTATIONS, TRANSLATIONS, Skeleton, angle_factor


@dataclass(frozen=True, eq=False)
class Read:
    """What a motion held when it was read from ``file``: :meth:`Motion.unchanged` compares."""

    file: Origin
    values: np.ndarray
    skeleton: Skeleton
    frame_rate: float
    first_frame: int
    header: tuple[str, ...]
    line_order: tuple[str, ...] | None
    style: TextStyle


DEFAULT_FRAME_RATE = 120.0
"""Frames per second assumed for an AMC without a rate (CMU and HDM05 record at 120 Hz)."""


@dataclass(frozen=True, eq=False)
class Motion:
    """Channel values of a skeleton over consecutive frames, in file units.

    ``values`` is float64 of shape (frames, channels), its columns in the
    canonical layout ``skeleton.channels``: the root's channels in its order,
    then each bone's dofs in bone order.  It is read-only: operations return
    new motions (a writeable array given here is copied first).  Frames are
    numbered from ``first_frame`` at ``frame_rate`` per second.  ``header``
    and ``line_order`` are what the AMC file had (its header lines, and the
    order of the bone lines in a frame), ``style`` how its text was laid out
    (line endings, exponents), so that it is written back as found; ``origin``
    is the file it was read from, with what was read, so that a motion written
    back unchanged is the file's very bytes.
    """

    skeleton: Skeleton
    values: np.ndarray
    frame_rate: float = DEFAULT_FRAME_RATE
    first_frame: int = 1
    header: tuple[str, ...] = (":FULLY-SPECIFIED", ":DEGREES")
    line_order: tuple[str, ...] | None = None
    style: TextStyle = PLAIN
    origin: Read | None = None

    def __post_init__(self) -> None:
        values = self.values
        if not isinstance(values, np.ndarray) or values.dtype != np.float64 or values.flags.writeable:
            values = np.array(values, dtype=np.float64)
            values.flags.writeable = False
        channels = len(self.skeleton.channels)
        if values.ndim != 2 or values.shape[1] != channels:
            raise ValueError(f"values must have shape (frames, {channels}) for this skeleton, got {values.shape}")
        if not self.frame_rate > 0:
            raise ValueError(f"frame_rate must be positive, got {self.frame_rate}")
        object.__setattr__(self, "values", values)

    def unchanged(self) -> bool:
        """Whether this motion is exactly what was read from its file, and the file is as it was."""
        o = self.origin
        return (
            o is not None
            and o.values is self.values
            and o.skeleton is self.skeleton
            and (o.frame_rate, o.first_frame, o.header, o.line_order, o.style)
            == (self.frame_rate, self.first_frame, self.header, self.line_order, self.style)
            and o.file.intact()
        )

    def read_from(self, source: Source) -> Motion:
        """This motion (just read) marked as read from ``source``: see :attr:`origin`."""
        file = Origin.of(source)
        if file is None:
            return self
        origin = Read(
            file,
            self.values,
            self.skeleton,
            self.frame_rate,
            self.first_frame,
            self.header,
            self.line_order,
            self.style,
        )
        return replace(self, origin=origin)

    def __repr__(self) -> str:
        return (
            f"Motion(skeleton={self.skeleton.name!r}, frames={self.frames} from {self.first_frame}, "
            f"channels={self.values.shape[1]}, frame_rate={self.frame_rate:g})"
        )

    @property
    def frames(self) -> int:
        """The number of frames."""
        return self.values.shape[0]

    @property
    def last_frame(self) -> int:
        """The number of the last frame (``first_frame - 1`` when there are none)."""
        return self.first_frame + self.frames - 1

    @property
    def channels(self) -> tuple[tuple[str, str], ...]:
        """(joint, dof) of each column of ``values``."""
        return self.skeleton.channels

    @property
    def times(self) -> np.ndarray:
        """Seconds of each frame from the first."""
        return np.arange(self.frames) / self.frame_rate

    def columns(self, joint: str, dofs: str | tuple[str, ...] | None = None) -> list[int]:
        """Column indices of a joint's channels ("root" or a bone), all or the named dofs."""
        available = self.skeleton.dofs(joint)
        wanted = available if dofs is None else ((dofs,) if isinstance(dofs, str) else tuple(dofs))
        start = self.skeleton.first_column(joint)
        result = []
        for dof in wanted:
            dof = dof.lower()
            if dof not in available:
                raise UnknownNameError(
                    f"joint '{joint}' has no channel '{dof}' (it has {', '.join(available) or 'none'})"
                )
            result.append(start + available.index(dof))
        return result

    def channel(self, joint: str, dof: str) -> np.ndarray:
        """One channel over all frames (a read-only view)."""
        return self.values[:, self.columns(joint, dof)[0]]

    def positions(self, *, start: bool = False, meters: bool = False, workers: int | None = None) -> np.ndarray:
        """World positions (frames, joints, 3) by forward kinematics, joints in
        ``skeleton.joint_names`` order: the root's position, then each bone's end
        point (its start point, the end of its parent, with ``start=True``).
        In file length units, or metres with ``meters=True`` (by the skeleton's
        length unit: ``skeleton.length_unit``, ``length_source``).  NaN in a channel
        gives NaN for that joint and the joints below it."""
        tree = self.skeleton.tree
        positions, _, _ = forward_kinematics(self.values, tree, workers=workers)
        if start:
            positions = positions[:, np.maximum(tree.parent, 0)]
        return positions * self.skeleton.meters_per_unit if meters else positions

    def rotations(self, *, local: bool = False, quaternions: bool = False, workers: int | None = None) -> np.ndarray:
        """Each joint's rotation per frame: (frames, joints, 3, 3) matrices, or
        (frames, joints, 4) unit quaternions (w, x, y, z), w >= 0.  World
        rotations by default; ``local=True`` gives C M C^T, a joint's own
        rotation in world-aligned axes (what the HDM05 toolbox stores)."""
        _, world, own = forward_kinematics(
            self.values, self.skeleton.tree, world=not local, local=local, workers=workers
        )
        matrices = own if local else world
        assert matrices is not None  # asked for
        return matrices_to_quaternions(matrices) if quaternions else matrices

    def apply(self, step: str, **options: Any) -> Motion:
        """Deprecated: ``motion.apply("median", size=5)`` is ``motion.median(size=5)``, the one
        spelling of a step on a motion (a step named in a variable: ``mt.Pipeline.of(name,
        **options).apply(motion)``)."""
        _deprecated(f"motion.apply({step!r}, ...)", f"motion.{step}(...)")
        return lookup(step)(self, **options)

    def __getattr__(self, name: str) -> Callable[..., Motion]:
        # Registered steps are methods: motion.median(size=5), motion.slerp(frames=(10, 20)).
        if name.startswith("_") or not is_step(name):
            raise AttributeError(f"'Motion' object has no attribute {name!r}")
        step = lookup(name)
        return lambda **options: step(self, **options)

    def filter(self, kind: str, size: int, joints: Iterable[str] | None = None, **options: Any) -> Motion:
        """Deprecated: ``motion.filter("median", 5)`` is ``motion.median(size=5)``, the one
        spelling of a step on a motion (``mt.filter_motion(motion, kind, size=5)`` takes the kind
        as an argument)."""
        _deprecated(f"motion.filter({kind!r}, {size!r}, ...)", f"motion.{kind}(size={size!r}, ...)")
        return lookup(kind)(self, size=size, joints=None if joints is None else tuple(joints), **options)

    def crop(self, first: int, last: int) -> Motion:
        """Frames ``first`` .. ``last`` (frame numbers, both included) as a motion of their own."""
        if not self.first_frame <= first <= last <= self.last_frame:
            raise ValueError(
                f"frames {first}..{last} are not within the motion's frames {self.first_frame}..{self.last_frame}"
            )
        a = first - self.first_frame
        return replace(self, values=self.values[a : a + last - first + 1], first_frame=first)

    def splice(self, piece: Motion) -> Motion:
        """This motion with the frames of ``piece`` (a motion of the same skeleton, within this
        one's frames, as :meth:`crop` gives) put in their place; every other frame as it was."""
        if piece.skeleton.channels != self.skeleton.channels:
            raise ValueError("splice: the piece is a motion of another skeleton")
        if piece.skeleton != self.skeleton:  # its bones, units or offsets changed: no frame range holds that
            raise ValueError(
                "splice: the piece's skeleton has other lengths, units or offsets; only frames can be put in"
            )
        if not self.first_frame <= piece.first_frame <= piece.last_frame <= self.last_frame:
            raise ValueError(
                f"splice: frames {piece.first_frame}..{piece.last_frame} are not within "
                f"{self.first_frame}..{self.last_frame}"
            )
        values = self.values.copy()
        a = piece.first_frame - self.first_frame
        values[a : a + piece.frames] = piece.values
        values.flags.writeable = False
        return replace(self, values=values)

    def replace(self, **changes: Any) -> Motion:
        """A new motion with some fields changed (values are copied if writeable)."""
        return replace(self, **changes)

    def with_units(self, *, length_factor: float = 1.0, length: str | None = None, angle: str | None = None) -> Motion:
        """Lengths times ``length_factor`` (unit text ``length``) and angles in ``angle``
        ("deg" or "rad"), for the skeleton and the values alike."""
        skeleton = self.skeleton.with_units(length_factor=length_factor, length=length, angle=angle)
        turn = angle_factor(self.skeleton.angle_unit, angle)
        factors = np.array(
            [
                turn if dof in ROTATIONS else length_factor if dof in (*TRANSLATIONS, "l") else 1.0
                for _, dof in self.channels
            ]
        )
        values = self.values * factors
        values.flags.writeable = False
        header = tuple(_angle_header(line, skeleton.angle_unit) for line in self.header)
        return replace(self, skeleton=skeleton, values=values, header=header)

    def to_meters(self) -> Motion:
        """Lengths in metres (CMU and HDM05: file value / 0.45 * 0.0254).  The
        skeleton's ``:units length`` becomes 0.0254, which the Acclaim convention
        reads as metres, so that files written from the result say what they hold."""
        return self.with_units(length_factor=self.skeleton.meters_per_unit, length="0.0254")

    def to_radians(self) -> Motion:
        """Angles in radians (the skeleton's ``:units angle`` and the AMC header say so)."""
        return self.with_units(angle="rad")

    def to_degrees(self) -> Motion:
        """Angles in degrees."""
        return self.with_units(angle="deg")


def _angle_header(line: str, unit: str) -> str:
    word = line.strip().upper()
    if word in (":DEGREES", ":RADIANS"):
        return ":RADIANS" if unit == "rad" else ":DEGREES"
    return line


def _deprecated(old: str, new: str) -> None:
    warnings.warn(f"{old} is deprecated: write {new}", DeprecationWarning, stacklevel=3)
