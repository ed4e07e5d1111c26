"""The format table: what each file suffix stands for, and the one place that says it.

A row (:class:`Format`) names a suffix's codec: how a take of it is read and written, how a
skeleton is read from it, which skeleton convention its motions have, and the companion file
that holds its skeleton where the take does not (an ``.amc`` needs its ``.asf``).  Everything
that reads or writes a file by its name (the command line, batch, retarget, info, the viewer,
the exporters) asks this module; adding a format is its codec module and one row of
:data:`FORMATS`.
"""

from __future__ import annotations

import hashlib
import io
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import IO

import numpy as np

from .._io import output, read_source, regular_file
from ..model.motion import Motion
from ..model.skeleton import Skeleton, settle_length_unit
from .amc import read_amc, read_amc_frames, skeleton_path_for, write_amc
from .asf import read_asf, write_asf
from .bvh import read_bvh, read_bvh_frames, write_bvh
from .cut import Cut
from .gltf_read import animation_names, read_gltf

ReadTake = Callable[..., Motion]  # (path, skeleton or None, frame_rate, unit, workers) -> Motion
ReadFrames = Callable[..., tuple[Motion, Cut | None]]  # the same, and where the file breaks off


@dataclass(frozen=True)
class Format:
    """One file format: its suffix (lower case, with the dot) and its codec's functions.

    ``read`` takes ``(path, skeleton, frame_rate, unit, workers)`` (``skeleton`` is the
    companion's, or None for a format that holds its own) and returns the take; ``write`` writes
    a motion of ``convention``'s skeletons.  ``read_skeleton`` reads a skeleton file of this
    format (an ``.asf``, or the hierarchy of a ``.bvh``), ``write_skeleton`` writes one.
    ``companion`` is the suffix of the skeleton file a take needs beside it, or None;
    ``states_unit`` whether its files state their length unit (a BVH file does not);
    ``takes`` the names of the takes a file holds where it may hold several (glTF's animations;
    ``read`` gives the first); ``read_frames`` reads as ``read`` does but keeps the frames of a
    file that breaks off (:func:`read_take_frames`), where the format can break off so;
    ``layout`` whether both also take ``layout=`` (:func:`read_file`: a text format that keeps
    how its text is laid out, to write it back so).
    """

    suffix: str
    name: str
    convention: str
    read: ReadTake | None = None
    write: Callable[[Motion, str | os.PathLike], None] | None = None
    read_skeleton: Callable[[str | os.PathLike], Skeleton] | None = None
    write_skeleton: Callable[[Skeleton, str | os.PathLike | IO[bytes]], None] | None = None
    companion: str | None = None
    states_unit: bool = True
    takes: Callable[[str | os.PathLike], list[str]] | None = None
    read_frames: ReadFrames | None = None
    layout: bool = False

    @property
    def holds_takes(self) -> bool:
        """Whether files of this format hold motions (an ``.asf`` holds a skeleton only)."""
        return self.read is not None


def _read_amc(path, skeleton, frame_rate, unit, workers, layout=True) -> Motion:
    return read_amc(path, skeleton, frame_rate, workers=workers, layout=layout)


def _read_bvh(path, skeleton, frame_rate, unit, workers, layout=True) -> Motion:
    return read_bvh(path, unit=unit, frame_rate=frame_rate, layout=layout)


def _amc_frames(path, skeleton, frame_rate, unit, workers, layout=True) -> tuple[Motion, Cut | None]:
    return read_amc_frames(path, skeleton, frame_rate, workers=workers, layout=layout)


def _bvh_frames(path, skeleton, frame_rate, unit, workers, layout=True) -> tuple[Motion, Cut | None]:
    return read_bvh_frames(path, unit=unit, frame_rate=frame_rate, layout=layout)


def _bvh_skeleton(path) -> Skeleton:
    return read_bvh(path).skeleton


def _read_gltf(path, skeleton, frame_rate, unit, workers) -> Motion:
    motion = read_gltf(path, frame_rate=frame_rate)
    return motion if unit is None else motion.replace(skeleton=motion.skeleton.with_length_unit(unit, "given"))


FORMATS: dict[str, Format] = {
    ".asf": Format(".asf", "ASF", "asf", read_skeleton=read_asf, write_skeleton=write_asf),
    ".amc": Format(
        ".amc", "ASF/AMC", "asf", _read_amc, write_amc, companion=".asf", read_frames=_amc_frames, layout=True
    ),
    ".bvh": Format(
        ".bvh",
        "BVH",
        "bvh",
        _read_bvh,
        write_bvh,
        read_skeleton=_bvh_skeleton,
        states_unit=False,
        read_frames=_bvh_frames,
        layout=True,
    ),
    # glTF takes are read as BVH motions and written by the export step (views/export.py)
    ".glb": Format(".glb", "glTF binary", "bvh", _read_gltf, takes=animation_names),
    ".gltf": Format(".gltf", "glTF", "bvh", _read_gltf, takes=animation_names),
    # written by the export step only: here so that a file of them read as a take gets told so
    ".fbx": Format(".fbx", "FBX", "bvh"),
    ".usd": Format(".usd", "USD", "bvh"),
    ".usda": Format(".usda", "USD", "bvh"),
    ".usdc": Format(".usdc", "USD", "bvh"),
}


def take_suffixes() -> tuple[str, ...]:
    """The suffixes of the formats that hold takes (``.amc``, ``.bvh``, ...)."""
    return tuple(s for s, f in FORMATS.items() if f.holds_takes)


def skeleton_suffixes() -> tuple[str, ...]:
    """The suffixes of the files a skeleton is read from (``.asf``, ``.bvh``, ...)."""
    return tuple(s for s, f in FORMATS.items() if f.read_skeleton is not None)


def _listing(suffixes: tuple[str, ...]) -> str:
    return ", ".join(suffixes[:-1]) + (" or " if len(suffixes) > 1 else "") + suffixes[-1]


def format_of(path: str | os.PathLike) -> Format:
    """The format of a take file by its suffix (any case); ValueError naming the file otherwise."""
    found = FORMATS.get(os.path.splitext(os.fspath(path))[1].lower())  # not Path: batch asks for every take
    if found is None or not found.holds_takes:
        note = ""
        if found is not None and found.read_skeleton is None:  # a format only the export step writes
            note = f"motiontheater writes {found.name} (the export step) but does not read it; "
        raise ValueError(f"{os.fspath(path)}: {note}a take's file name must end in {_listing(take_suffixes())}")
    return found


def format_for(convention: str) -> Format:
    """The format a motion of a skeleton convention (``"asf"``, ``"bvh"``) is written in."""
    for row in FORMATS.values():
        if row.holds_takes and row.write is not None and row.convention == convention:
            return row
    raise ValueError(f"no format writes motions of {convention!r} skeletons")


def suffix_for(convention: str) -> str:
    """The take suffix a motion of a skeleton convention (``"asf"``, ``"bvh"``) is written as."""
    return format_for(convention).suffix


def take_suffix(path: str | os.PathLike) -> str:
    """The lower-case suffix of a take file; ValueError naming the file when no format holds takes so."""
    return format_of(path).suffix


def skeleton_for(
    path: str | os.PathLike, asf: str | os.PathLike | None = None, folders: dict[Path, list[Path]] | None = None
) -> Path | None:
    """The skeleton file a take needs beside it: ``asf`` when given, else the one found beside it
    by the CMU/HDM05 naming (``folders`` as for :func:`~motiontheater.formats.amc.skeleton_path_for`);
    None for a take that holds its own skeleton (BVH)."""
    if format_of(path).companion is None:
        return None
    if asf is not None:
        return Path(asf)
    return skeleton_path_for(path, folders)


def _skeleton_format(path: str | os.PathLike) -> Format:
    """The format a skeleton file is read in, by its suffix; ValueError naming the file otherwise."""
    row = FORMATS.get(Path(path).suffix.lower())
    if row is None or row.read_skeleton is None:
        raise ValueError(f"{os.fspath(path)}: a skeleton's file name must end in {_listing(skeleton_suffixes())}")
    return row


def skeleton_convention(path: str | os.PathLike) -> str:
    """The convention of the skeleton a skeleton file of this name holds (``.asf``: ``"asf"``)."""
    return _skeleton_format(path).convention


def read_skeleton(path: str | os.PathLike, unit: str | None = None) -> Skeleton:
    """The skeleton of a file (an ``.asf``, or a ``.bvh``'s hierarchy), its length unit settled
    (``unit`` when given).  Files of the same bytes are parsed once (a database has a few
    skeletons and thousands of takes; a subject's ASF is copied into every session's folder);
    a changed file is read again.  FileNotFoundError naming a missing file."""
    row = _skeleton_format(path)
    assert row.read_skeleton is not None
    data, _ = read_source(path)
    key = (hashlib.sha256(data).digest(), row.suffix, unit)
    if key not in _PARSED:
        if len(_PARSED) >= 256:
            _PARSED.pop(next(iter(_PARSED)))  # the oldest
        _PARSED[key] = settle_length_unit(row.read_skeleton(path), unit)
    return _PARSED[key]


_PARSED: dict[tuple[bytes, str, str | None], Skeleton] = {}  # skeletons by the digest of their file's bytes


def read_take(
    path: str | os.PathLike,
    asf: str | os.PathLike | None = None,
    frame_rate: float | None = None,
    unit: str | None = None,
    *,
    workers: int | None = None,
) -> Motion:
    """The motion of a take file, read by its suffix's format: an AMC with its skeleton (``asf``,
    or the ASF found beside it), a BVH with its own.  ``frame_rate`` (Hz) is an AMC's rate where
    its header states none, and a BVH's in place of its Frame Time.  ``unit`` is its length unit
    (m, cm, mm, in, or a number L for inch / L) when given: a BVH's is detected from its size
    otherwise, an ASF's is its ``:units length``.  The take must hold at least one frame."""
    return _read_take(path, asf, frame_rate, unit, workers, whole_frames=False, layout=True)[0]


def read_take_frames(
    path: str | os.PathLike,
    asf: str | os.PathLike | None = None,
    frame_rate: float | None = None,
    unit: str | None = None,
    *,
    workers: int | None = None,
    layout: bool = True,
) -> tuple[Motion, Cut | None]:
    """:func:`read_take`, but of a file that breaks off before its header says it ends, or goes
    on past it (a BVH of fewer or more rows than ``Frames:`` says, a last frame cut short), the
    frames it holds whole, and how it disagrees (None for a whole file, or a format that cannot
    break off so).  ``layout`` as for :func:`read_file`."""
    return _read_take(path, asf, frame_rate, unit, workers, whole_frames=True, layout=layout)


def _read_take(
    path: str | os.PathLike,
    asf: str | os.PathLike | None,
    frame_rate: float | None,
    unit: str | None,
    workers: int | None,
    *,
    whole_frames: bool,
    layout: bool,
) -> tuple[Motion, Cut | None]:
    format_of(path)  # an unknown suffix is told before a missing file
    regular_file(path)
    companion = skeleton_for(path, asf)
    skeleton = None if companion is None else read_skeleton(companion, unit)
    motion, cut = read_file(path, skeleton, frame_rate, unit, workers, whole_frames=whole_frames, layout=layout)
    return require_frames(motion, path), cut


def read_file(
    path: str | os.PathLike,
    skeleton: Skeleton | None,
    frame_rate: float | None,
    unit: str | None,
    workers: int | None,
    *,
    whole_frames: bool = False,
    layout: bool = True,
) -> tuple[Motion, Cut | None]:
    """The motion of a take file by its format's reader, its skeleton read already (an AMC's;
    None where the file holds its own), and None; with ``whole_frames``, where the format can
    break off, the frames it holds whole and where it breaks off (:func:`read_take_frames`).
    ``layout=False`` reads the values and the header only, not how a text format lays them out
    (line endings, exponents, the order of an AMC frame's lines): for a take that is looked at,
    not written back (what is written from it is laid out plainly)."""
    row = format_of(path)
    options = {"layout": layout} if row.layout else {}
    if whole_frames and row.read_frames is not None:
        return row.read_frames(path, skeleton, frame_rate, unit, workers, **options)
    assert row.read is not None
    return row.read(path, skeleton, frame_rate, unit, workers, **options), None


def require_frames(motion: Motion, path: str | os.PathLike) -> Motion:
    """The motion; ValueError naming the file when it has no frame to work on."""
    if not motion.frames:
        raise ValueError(f"{os.fspath(path)}: the take holds no frames")
    return motion


def companion_path(motion: Motion, path: str | os.PathLike) -> Path | None:
    """Where the skeleton file of a take written to ``path`` goes (beside it, named as the take's
    stem: ``out/y.amc`` -> ``out/y.asf``), or None when the take's format holds its skeleton."""
    companion = format_of(path).companion
    return None if companion is None else Path(path).with_suffix(companion)


def states_unit(path: str | os.PathLike) -> bool:
    """Whether a file of this name states its length unit: False for a format that does not (BVH),
    True for the others and for files no format of the table reads (positions, markers)."""
    row = FORMATS.get(Path(path).suffix.lower())
    return row is None or row.states_unit


def write_skeleton(skeleton: Skeleton, path: str | os.PathLike) -> None:
    """Write a skeleton file in the format its suffix names (an ``.asf``)."""
    row = FORMATS.get(Path(path).suffix.lower())
    if row is None or row.write_skeleton is None:
        raise ValueError(f"{os.fspath(path)}: no format writes skeletons as {Path(path).suffix or 'this'}")
    row.write_skeleton(skeleton, path)


def write_take_with_skeleton(
    motion: Motion, path: str | os.PathLike, *, allow_non_finite: bool = False, replace: bool = False
) -> Path | None:
    """Write a take (as :func:`write_take`) and, for a format that keeps its skeleton beside the
    take (an AMC's ASF), the skeleton file it is then read with, unless the one its name finds
    there (:func:`skeleton_for`) holds that skeleton already, byte for byte.  The file written is
    named after the take (``out/y.amc`` -> ``out/y.asf``); one of that name holding another
    skeleton is what other takes there are read with, and is kept: ValueError before anything is
    written, unless ``replace``.  Returns the skeleton file written, or None."""
    target = companion_path(motion, path)
    data = None if target is None else skeleton_text(motion.skeleton, target)
    if target is not None and data is not None:
        try:
            found: Path | None = skeleton_for(path)
        except (FileNotFoundError, NotADirectoryError):
            found = None
        if (found is not None and file_bytes(found) == data) or not companion_needed(target, data, replace=replace):
            data = None
    write_take(motion, path, allow_non_finite=allow_non_finite)
    if target is None or data is None:
        return None
    with output(target) as f:
        f.write(data)
    return target


def skeleton_text(skeleton: Skeleton, path: str | os.PathLike) -> bytes:
    """The bytes of the skeleton file ``path`` that holds ``skeleton`` (in the format of its suffix)."""
    row = _skeleton_format(path)
    if row.write_skeleton is None:
        raise ValueError(f"{os.fspath(path)}: no format writes skeletons as {Path(path).suffix or 'this'}")
    buffer = io.BytesIO()
    row.write_skeleton(skeleton, buffer)
    return buffer.getvalue()


def file_bytes(path: str | os.PathLike) -> bytes | None:
    """The bytes of a file, or None where there is none (nor, perhaps, its folder)."""
    try:
        return read_source(path)[0]
    except (FileNotFoundError, NotADirectoryError):
        return None


def companion_needed(path: str | os.PathLike, data: bytes, *, replace: bool = False) -> bool:
    """Whether the skeleton file ``path`` is to be written to hold ``data``: when it is absent (or,
    with ``replace``, holds other bytes), not when it holds them already.  ValueError when it holds
    another skeleton: takes beside it are read with that one."""
    existing = file_bytes(path)
    if existing is None or (replace and existing != data):
        return True
    if existing != data:
        raise ValueError(
            f"{os.fspath(path)} exists and holds another skeleton, which the takes beside it are read with: "
            "write the take elsewhere or under another name, or pass --in-place to replace that file "
            "(Python: replace=True)"
        )
    return False


def write_take(motion: Motion, path: str | os.PathLike, *, allow_non_finite: bool = False) -> None:
    """Write a motion in the format its suffix names; a motion of another convention is refused
    (``motiontheater convert`` turns one into the other), and so is one holding NaN or inf, unless
    ``allow_non_finite`` (ValueError naming the frames and channels: a file of ``nan`` tokens is one
    that most readers refuse)."""
    if not allow_non_finite and not np.isfinite(motion.values).all():
        raise ValueError(f"{os.fspath(path)}: {non_finite_text(motion)}")
    row = format_of(path)
    if row.write is None:
        raise ValueError(
            f"{os.fspath(path)}: {row.name} files are written by the export step: "
            f"motiontheater export TAKE -o {os.path.basename(os.fspath(path))}"
        )
    if motion.skeleton.convention != row.convention:
        other = suffix_for(motion.skeleton.convention)
        kind = f"{'an' if motion.skeleton.convention[0] in 'aeiou' else 'a'} {motion.skeleton.convention.upper()}"
        raise ValueError(
            f"{os.fspath(path)}: this is a motion of {kind} skeleton, which is written as {other}, not {row.suffix}; "
            f"name the output {other}, or convert it first (motiontheater convert)"
        )
    row.write(motion, path)


def non_finite_text(motion: Motion) -> str:
    """Where a motion holds values that are not numbers, in words, and what to do about it."""
    bad = ~np.isfinite(motion.values)
    frames = np.flatnonzero(bad.any(axis=1)) + motion.first_frame
    runs = np.split(frames, np.flatnonzero(np.diff(frames) > 1) + 1) if len(frames) else []
    spans = [f"{r[0]}" if len(r) == 1 else f"{r[0]}-{r[-1]}" for r in runs[:4]] + (["..."] if len(runs) > 4 else [])
    columns = np.flatnonzero(bad.any(axis=0))
    names = [
        f"{motion.skeleton.root.name if j == 'root' else j} {d}" for j, d in (motion.channels[c] for c in columns[:4])
    ]
    kinds = " and ".join(k for k, f in (("NaN", np.isnan), ("inf", np.isinf)) if f(motion.values).any())
    return (
        f"{int(bad.sum())} values are {kinds} (frames {', '.join(spans)}; channels {', '.join(names)}"
        f"{', ...' if len(columns) > 4 else ''}), which most readers refuse: fill the gaps (the fill_gaps "
        "step; --max-gap SECONDS for longer ones), or write them as they are with --allow-nan "
        "(Python: write_take(..., allow_non_finite=True))"
    )
