"""AMC (Acclaim Motion Capture): read and write, the numbers scanned in C."""

from __future__ import annotations

import contextlib
import dataclasses
import os
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mtcore import format_frames, format_number, scan_frames
from mtcore.errors import ChangedFileError, TruncatedError
from mtcore.text import copy_text, frame_line, line_breaks

from .._io import LINE_BREAK, PLAIN, Source, Text, TextStyle, decode, encode, mapped_source, open_regular, output
from ..model.errors import FormatError, SequenceError
from ..model.motion import DEFAULT_FRAME_RATE, Motion
from ..model.skeleton import Skeleton
from .cut import Cut

READ_BYTES = 8 << 20  # bytes read at a time when a take is streamed
HEAD_BYTES = 4 << 20  # the most of a take read to find its header and first frame

_RATE_KEYS = (":SAMPLES-PER-SECOND", ":SAMPLES_PER_SECOND", ":FRAME-RATE")


def skeleton_path_for(amc_path: str | os.PathLike, folders: dict[Path, list[Path]] | None = None) -> Path:
    """The ASF beside an AMC by the naming conventions of the big databases:
    CMU ``01_02.amc`` -> ``01.asf`` (or ``01-walk.asf``), HDM05
    ``HDM_bd_squat_003_120.amc`` -> ``HDM_bd.asf``, ``take.amc`` -> ``take.asf``.
    The longest matching name wins; FileNotFoundError when none matches.  ``folders`` keeps
    the ASFs of each folder looked in, for a caller that asks for many takes at once."""
    amc = Path(amc_path)
    if folders is None:
        folders = {}
    if amc.parent not in folders:
        folders[amc.parent] = [p for p in amc.parent.iterdir() if p.suffix.lower() == ".asf"]
    best = None
    for asf in folders[amc.parent]:
        stem = asf.stem.split("-")[0]
        rest = amc.stem[len(stem) :]
        matches = amc.stem.startswith(stem) and (rest == "" or rest[0] in "_-.")
        if matches and (best is None or len(stem) > len(best.stem.split("-")[0])):
            best = asf
    if best is None:
        raise FileNotFoundError(
            f"no skeleton for {amc}: no .asf in {amc.parent} matches its name (CMU 01_02.amc -> 01.asf, "
            "HDM05 HDM_bd_squat_003_120.amc -> HDM_bd.asf, take.amc -> take.asf); give it with --asf"
        )
    return best


def _layout(skeleton: Skeleton, joints) -> tuple[list[bytes], list[int], list[int]]:
    """Keys, first columns and channel counts of the given joints in the canonical layout."""
    joints = tuple(joints)
    return skeleton.derived(
        ("amc layout", joints),
        lambda: (
            [encode(j) for j in joints],
            [skeleton.first_column(j) for j in joints],
            [len(skeleton.dofs(j)) for j in joints],
        ),
    )


def _split_header(data: Text) -> tuple[list[tuple[int, str]], int, int]:
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
        pos = min(len(data), end + (2 if data[end : end + 2] == b"\r\n" else 1))
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
    source: Source,
    skeleton: Skeleton,
    frame_rate: float | None = None,
    *,
    workers: int | None = None,
    layout: bool = True,
) -> Motion:
    """Read an AMC file (path or file object) of ``skeleton`` into a :class:`Motion`.

    Bones may come in any order within a frame (and in another order than
    the ASF); bones without dofs may be listed or not; frames are numbered
    consecutively from any start.  The frame rate is the header's
    (``:SAMPLES-PER-SECOND``) when present, else ``frame_rate``, else
    :data:`~motiontheater.model.motion.DEFAULT_FRAME_RATE` (120, that of CMU and
    HDM05); a ``frame_rate`` that contradicts the header raises ValueError.
    Values stay in the skeleton's units.  Bad input raises a
    :class:`~mtcore.errors.FormatError` subclass naming the file, the line and
    what was expected; an AMC of another skeleton fails on its first unknown
    or missing bone.  Files of several megabytes are scanned on all cores;
    ``workers=1`` keeps to the calling thread (as batch jobs in processes should).
    ``layout=False`` reads the values and the header only, not how the text is laid out (line
    endings, exponents, the order of a frame's lines): for a take that is looked at, not
    written back (what is written from it is laid out plainly).
    """
    return _read_source(source, skeleton, frame_rate, workers, whole_frames=False, layout=layout)[0]


def read_amc_frames(
    source: Source,
    skeleton: Skeleton,
    frame_rate: float | None = None,
    *,
    workers: int | None = None,
    layout: bool = True,
) -> tuple[Motion, Cut | None]:
    """:func:`read_amc`, but of a file that breaks off in its last frame (a capture or a copy
    cut short), the frames before it, and where it breaks off (None for a whole file).  Such a
    motion has no file to be written back from: it is written anew, whole."""
    return _read_source(source, skeleton, frame_rate, workers, whole_frames=True, layout=layout)


def _read_source(
    source: Source,
    skeleton: Skeleton,
    frame_rate: float | None,
    workers: int | None,
    *,
    whole_frames: bool,
    layout: bool,
) -> tuple[Motion, Cut | None]:
    with mapped_source(source) as (data, name):
        try:
            try:
                return _read(data, name, skeleton, frame_rate, workers, layout).read_from(source), None
            except TruncatedError as e:
                if not whole_frames:
                    raise
                last = frame_line(data, 0, len(data), last=True)  # the frame the file breaks off in
                motion = _read(copy_text(data, 0, max(last, 0)), name, skeleton, frame_rate, workers, layout)
                reason = f"the file breaks off in its last frame: the {motion.frames} frames before it are whole"
                return motion, Cut(reason, e.line, motion.frames)
        except ChangedFileError:
            raise ChangedFileError(
                f"{name}: the file changed while it was read; read it again when it is whole"
            ) from None


def _read_header(
    data: Text, name: str | None, skeleton: Skeleton, frame_rate: float | None
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


def _read(
    data: Text,
    name: str | None,
    skeleton: Skeleton,
    frame_rate: float | None,
    workers: int | None,
    layout: bool = True,
) -> Motion:
    # Python reads a copy of the head (header, first frame, style); only the C scanner, which is
    # guarded against a file that shrinks meanwhile, reads a mapped file itself
    head = _head(data)
    header, body, header_lines, rate = _read_header(head, name, skeleton, frame_rate)
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
        line_order=_first_frame_order(head, body, set(joints)) if layout else None,
        style=TextStyle.of(data) if layout else PLAIN,
    )


def _head(data: Text) -> bytes:
    """The start of a take that holds its header and first frame (the first HEAD_BYTES at most):
    a take's first kilobytes, as a rule."""
    size = 1 << 16
    while True:
        head = copy_text(data, 0, size)
        if len(head) == len(data) or size >= HEAD_BYTES:
            return head
        body = _split_header(head)[1]
        if body < len(head) and frame_line(head, body + 1) != -1:
            return head
        size *= 4


def _check_angle_unit(header: list[tuple[int, str]], skeleton: Skeleton) -> None:
    for number, line in header:
        word = line.strip().upper()
        said = {":DEGREES": "deg", ":RADIANS": "rad"}.get(word)
        if said is not None and said != skeleton.angle_unit:
            raise FormatError(f"the AMC says {word} but its skeleton's angles are in {skeleton.angle_unit}", number)


def _first_frame_order(data: Text, body: int, joints: set[str]) -> tuple[str, ...]:
    """The bone lines of the first frame, in order: up to the next line of digits only."""
    window = 1 << 10  # a frame of 31 bones takes about 700 bytes
    while True:
        lines = LINE_BREAK.split(decode(data[body : body + window]))
        whole = body + window >= len(data)
        if not whole:
            lines.pop()  # it may be cut short
        order: list[str] = []
        for line in lines[1:]:
            words = line.split(None, 1)
            if not words or words[0].startswith("#"):
                continue
            if len(words) == 1 and words[0].isascii() and words[0].isdigit():
                return tuple(order)  # the next frame
            if words[0] in joints:
                order.append(words[0])
        if whole:
            return tuple(order)
        window *= 4


def write_amc(motion: Motion, target: Source) -> None:
    """Write a motion as AMC text to a path (atomically) or a binary file object.

    The header is the motion's (its rate line updated, or added when the rate
    is not the default); bone lines follow the motion's ``line_order`` when it
    has one, else the root and the bones with dofs in skeleton order.  Every
    number is the shortest text that reads back to exactly the same float64,
    lines and exponents laid out as the file read was (``motion.style``); a
    motion written back unchanged is its file's very bytes.
    """
    if motion.unchanged() and motion.origin is not None and motion.origin.file.copy_to(target):
        return
    with amc_writer(motion, target) as write:
        write(motion.values, motion.first_frame)


@contextlib.contextmanager
def amc_writer(motion: Motion, target: Source) -> Iterator[Callable[[np.ndarray, int], None]]:
    """A function ``write(values, first_frame)`` that appends frames to an AMC with the header,
    line order and skeleton of ``motion`` (its values are not written): :func:`write_amc` a
    piece at a time.  A path is replaced only when the block ends without an error."""
    keys, offsets, counts = _layout(motion.skeleton, _write_order(motion.skeleton, motion.line_order))
    style = motion.style
    frames = 0

    def write(values: np.ndarray, first: int) -> None:
        nonlocal frames
        format_frames(values, first, keys, offsets, counts, f, frame_newline=style.frame_newline, **style.numbers())
        frames += len(values)

    with output(target) as f:
        f.write(style.lines(_header_lines(motion)))
        yield write
        if not style.final_newline and f.seekable() and f.tell():  # the file read ended without a break
            f.truncate(f.tell() - len(style.frame_newline if frames and not keys else style.newline))


@dataclass(frozen=True)
class AmcStream:
    """An AMC take read a piece at a time, for takes too large for memory (see :func:`open_amc`).

    ``motion`` holds everything but the frames (skeleton, rate, header, line
    order; no values); :meth:`pieces` reads the frames from the start each time
    it is called.
    """

    path: str
    motion: Motion
    body: int  # offset of the first frame line
    header_lines: int
    read_bytes: int = READ_BYTES

    def pieces(self) -> Iterator[np.ndarray]:
        """The frames, a piece of about ``read_bytes`` of text at a time, checked to be consecutive."""
        skeleton = self.motion.skeleton
        keys, offsets, counts = _layout(skeleton, skeleton.joint_names)
        pending, lines_done, expected = b"", self.header_lines, None
        with open_regular(self.path) as f:
            f.seek(self.body)
            while True:
                more = f.read(self.read_bytes)
                text = pending + more
                # whole frames only: cut at the last frame line of the text (not at its very start)
                cut = frame_line(text, 1, len(text), last=True) if more else len(text)
                if cut <= 0:
                    pending = text
                    continue
                piece, pending = text[:cut], text[cut:]
                try:
                    values, first = scan_frames(
                        piece, keys, offsets, counts, len(skeleton.channels), noun="bone", workers=1
                    )
                except FormatError as e:
                    raise e.at(self.path, lines_done) from None
                if len(values):
                    if expected is not None and first != expected:
                        raise SequenceError(
                            f"frame number {first} out of sequence: expected {expected}", lines_done + 1, self.path
                        )
                    expected = first + len(values)
                    yield values
                lines_done += line_breaks(piece)
                if not more:
                    return


def open_amc(
    path: str | os.PathLike, skeleton: Skeleton, frame_rate: float | None = None, *, read_bytes: int = READ_BYTES
) -> AmcStream:
    """An AMC take to read a piece at a time (:class:`AmcStream`); the header is read and checked
    now, as :func:`read_amc` does, and the first frame's number and bone order from the first piece."""
    with open_regular(path) as f:
        head = f.read(read_bytes)
    name = os.fspath(path)
    header, body, header_lines, rate = _read_header(head, name, skeleton, frame_rate)
    start = frame_line(head, body)
    first = int(LINE_BREAK.split(decode(head[start:]), 1)[0]) if start != -1 else 1
    with open_regular(path) as f:
        f.seek(max(0, os.fstat(f.fileno()).st_size - 1))
        ends_in_a_break = f.read(1) in (b"", b"\n", b"\r")
    motion = Motion(
        skeleton,
        np.zeros((0, len(skeleton.channels))),
        rate,
        first,
        tuple(text for _, text in header),
        _first_frame_order(head, body, set(skeleton.joint_names)),
        dataclasses.replace(TextStyle.of(head), final_newline=ends_in_a_break),
    )
    return AmcStream(name, motion, body, header_lines, read_bytes)


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
