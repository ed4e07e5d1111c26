"""Takes by file name: the reader and writer a suffix stands for, chosen in this one place."""

from __future__ import annotations

import os
from pathlib import Path

from .amc import read_amc, skeleton_path_for, write_amc
from .asf import read_asf
from .bvh import read_bvh, write_bvh
from .motion import Motion
from .skeleton import settle_length_unit

TAKE_SUFFIXES = (".amc", ".bvh")
CONVENTIONS = {".amc": "asf", ".bvh": "bvh"}  # the skeleton convention a take file holds


def take_suffix(path: str | os.PathLike) -> str:
    """The lower-case suffix of a take file (.amc or .bvh); ValueError naming the file otherwise."""
    suffix = Path(path).suffix.lower()
    if suffix not in TAKE_SUFFIXES:
        raise ValueError(f"{os.fspath(path)}: a take's file name must end in .amc or .bvh")
    return suffix


def skeleton_for(
    path: str | os.PathLike, asf: str | os.PathLike | None = None, folders: dict[Path, list[Path]] | None = None
) -> Path:
    """The ASF of an AMC take: ``asf`` when given, else the one beside it by the CMU/HDM05 naming
    (``folders`` as for :func:`~motiontheater.amc.skeleton_path_for`)."""
    if asf is not None:
        return Path(asf)
    return skeleton_path_for(path, folders)


def read_take(
    path: str | os.PathLike,
    asf: str | os.PathLike | None = None,
    frame_rate: float | None = None,
    unit: str | None = None,
) -> Motion:
    """The motion of an AMC (with its skeleton: ``asf``, or the ASF found beside it) or a BVH file.
    ``unit`` is its length unit (m, cm, mm, in, or a number L for inch / L) when given: a BVH's
    is detected from its size otherwise, an ASF's is its ``:units length``.  The take must hold at
    least one frame."""
    suffix = take_suffix(path)
    if not os.path.exists(path):
        raise FileNotFoundError(f"{os.fspath(path)}: no such file")
    if suffix == ".bvh":
        return require_frames(read_bvh(path, unit=unit), path)
    skeleton = settle_length_unit(read_asf(skeleton_for(path, asf)), unit)
    return require_frames(read_amc(path, skeleton, frame_rate=frame_rate), path)


def require_frames(motion: Motion, path: str | os.PathLike) -> Motion:
    """The motion; ValueError naming the file when it has no frame to work on."""
    if not motion.frames:
        raise ValueError(f"{os.fspath(path)}: the take holds no frames")
    return motion


def write_take(motion: Motion, path: str | os.PathLike) -> None:
    """Write a motion in the format its suffix names; a motion of the other convention is refused
    (``motiontheater convert`` turns one into the other)."""
    suffix = take_suffix(path)
    if motion.skeleton.convention != CONVENTIONS[suffix]:
        other = ".bvh" if suffix == ".amc" else ".amc"
        kind = "an ASF" if motion.skeleton.convention == "asf" else "a BVH"
        raise ValueError(
            f"{os.fspath(path)}: this is a motion of {kind} skeleton, which is written as {other}, not {suffix}; "
            f"name the output {other}, or convert it first (motiontheater convert)"
        )
    (write_bvh if suffix == ".bvh" else write_amc)(motion, path)
