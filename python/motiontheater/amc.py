"""AMC (Acclaim Motion Capture): read and write, the numbers scanned in C."""

from __future__ import annotations

import os
import re
from pathlib import Path

from mtcore import format_frames, format_number, scan_frames
from mtcore.errors import FormatError

from ._io import Source, decode, encode, mapped_source, output
from .motion import DEFAULT_FRAME_RATE, Motion
from .skeleton import Skeleton

_RATE_KEYS = (":SAMPLES-PER-SECOND", ":SAMPLES_PER_SECOND", ":FRAME-RATE")


def skeleton_path_for(amc_path: str | os.PathLike) -> Path:
    """The ASF beside an AMC by the naming conventions of the big databases:
    CMU ``01_02.amc`` -> ``01.asf`` (or ``01-walk.asf``), HDM05
    ``HDM_bd_squat_003_120.amc`` -> ``HDM_bd.asf``, ``take.amc`` -> ``take.asf``.
    The longest matching name wins; FileNotFoundError when none matches."""
    amc = Path(amc_path)
    best = None
    for asf in amc.parent.iterdir():
        if asf.suffix.lower() != ".asf":
            continue
        stem = asf.stem.split("-")[0]
        rest = amc.stem[len(stem) :]
        if amc.stem.startswith(stem) and (rest == "" or rest[0] in "_-."):
            if best is None or len(stem) > len(best.stem.split("-")[0]):
                best = asf
    if best is None:
        raise FileNotFoundError(f"no skeleton (.asf) for {amc} in {amc.parent}")
    return best


def _layout(skeleton: Skeleton, joints) -> tuple[list[bytes], list[int], list[int]]:
    """Keys, first columns and channel counts of the given joints in the canonical layout."""
    return (
        [encode(j) for j in joints],
        [skeleton.first_column(j) for j in joints],
        [len(skeleton.dofs(j)) for j in joints],
    )


def _split_header(data: bytes) -> tuple[list[tuple[int, str]], int, int]:
    """(line number, text) of the header lines (comments and ':' keywords),
    the byte offset of the body and the number of lines before it."""
    header, pos, lines = [], 0, 0
    while pos < len(data):
        ends = [i for i in (data.find(b"\n", pos), data.find(b"\r", pos)) if i != -1]
        end = min(ends, default=len(data))
        line = data[pos:end].strip()
        if line and not line.startswith((b"#", b":")):
            break
        lines += 1
        if line:
            header.append((lines, decode(line)))
        pos = end + (2 if data[end : end + 2] == b"\r\n" else 1)
    return header, pos, lines


def _header_rate(header: list[tuple[int, str]]) -> float | None:
    for number, line in header:
        words = line.split()
        if words and words[0].upper() in _RATE_KEYS:
            try:
                return float(words[1])
            except (IndexError, ValueError):
                raise FormatError(f"expected a number of frames per second after {words[0]}", number) from None
    return None


def read_amc(
    source: Source, skeleton: Skeleton, frame_rate: float | None = None, *, workers: int | None = None
) -> Motion:
    """Read an AMC file (path or file object) of ``skeleton`` into a :class:`Motion`.

    Bones may come in any order within a frame (and in another order than
    the ASF); bones without dofs may be listed or not; frames are numbered
    consecutively from any start.  The frame rate is the header's
    (``:SAMPLES-PER-SECOND``) when present, else ``frame_rate``, else
    :data:`~motiontheater.motion.DEFAULT_FRAME_RATE` (120, that of CMU and
    HDM05); a ``frame_rate`` that contradicts the header raises ValueError.
    Values stay in the skeleton's units.  Bad input raises a
    :class:`~mtcore.errors.FormatError` subclass naming the file, the line and
    what was expected; an AMC of another skeleton fails on its first unknown
    or missing bone.  Files of several megabytes are scanned on all cores;
    ``workers=1`` keeps to the calling thread (as batch jobs in processes should).
    """
    with mapped_source(source) as (data, name):
        return _read(data, name, skeleton, frame_rate, workers)


def _read_header(
    data: bytes, name: str | None, skeleton: Skeleton, frame_rate: float | None
) -> tuple[list[tuple[int, str]], int, int, float]:
    """The header lines as :func:`_split_header` gives them, where the frames
    begin, the lines before them, and the frame rate (the header's, else
    ``frame_rate``, else the default), checked against the skeleton."""
    header, body, header_lines = _split_header(data)
    try:
        rate = _header_rate(header)
        _check_angle_unit(header, skeleton)
    except FormatError as e:
        raise e.at(name) from None
    if rate is not None and frame_rate is not None and rate != frame_rate:
        raise ValueError(f"{name}: the header says {rate:g} frames per second, frame_rate={frame_rate:g}")
    return header, body, header_lines, rate or frame_rate or DEFAULT_FRAME_RATE


def _read(data: bytes, name: str | None, skeleton: Skeleton, frame_rate: float | None, workers: int | None) -> Motion:
    header, body, header_lines, rate = _read_header(data, name, skeleton, frame_rate)
    joints = skeleton.joint_names
    keys, offsets, counts = _layout(skeleton, joints)
    try:
        values, first = scan_frames(
            data, keys, offsets, counts, len(skeleton.channels), start=body, noun="bone", workers=workers
        )
    except FormatError as e:
        raise e.at(name, header_lines) from None
    values.flags.writeable = False
    return Motion(
        skeleton=skeleton,
        values=values,
        frame_rate=rate,
        first_frame=first if len(values) else 1,
        header=tuple(text for _, text in header),
        line_order=_first_frame_order(data, body, set(joints)),
    )


def _check_angle_unit(header: list[tuple[int, str]], skeleton: Skeleton) -> None:
    for number, line in header:
        word = line.strip().upper()
        said = {":DEGREES": "deg", ":RADIANS": "rad"}.get(word)
        if said is not None and said != skeleton.angle_unit:
            raise FormatError(f"the AMC says {word} but its skeleton's angles are in {skeleton.angle_unit}", number)


_NEXT_FRAME_LINE = re.compile(rb"[\r\n][ \t]*\d+[ \t]*(?=[\r\n]|$)")


def _first_frame_order(data: bytes, body: int, joints: set[str]) -> tuple[str, ...]:
    """The bone lines of the first frame, in order."""
    following = _NEXT_FRAME_LINE.search(data, body + 1)
    block = data[body : following.start() if following else len(data)]
    order = []
    for line in re.split(rb"\r\n|\r|\n", block)[1:]:
        words = line.split(None, 1)
        if words and not words[0].startswith(b"#"):
            name = decode(words[0])
            if name in joints:
                order.append(name)
    return tuple(order)


def write_amc(motion: Motion, target: Source) -> None:
    """Write a motion as AMC text to a path (atomically) or a binary file object.

    The header is the motion's (its rate line updated, or added when the rate
    is not the default); bone lines follow the motion's ``line_order`` when it
    has one, else the root and the bones with dofs in skeleton order.  Every
    number is the shortest text that reads back to exactly the same float64.
    """
    keys, offsets, counts = _layout(motion.skeleton, _write_order(motion.skeleton, motion.line_order))
    with output(target) as f:
        f.write(encode("".join(line + "\n" for line in _header_lines(motion))))
        format_frames(motion.values, motion.first_frame, keys, offsets, counts, f.write)


def _write_order(skeleton: Skeleton, line_order: tuple[str, ...] | None) -> list[str]:
    """The bones of a frame as written: those of ``line_order``, then the others with dofs in skeleton order."""
    joints = list(line_order or ())
    return joints + [j for j in skeleton.joint_names if j not in joints and skeleton.dofs(j)]


def _header_lines(motion: Motion) -> list[str]:
    lines, rate_written = [], False
    for line in motion.header:
        words = line.split()
        if words and words[0].upper() in _RATE_KEYS:
            line = f"{words[0]} {format_number(motion.frame_rate)}"
            rate_written = True
        lines.append(line)
    if not rate_written and motion.frame_rate != DEFAULT_FRAME_RATE:
        lines.append(f":SAMPLES-PER-SECOND {format_number(motion.frame_rate)}")
    return lines
