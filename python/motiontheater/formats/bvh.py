"""BVH (Biovision Hierarchy): read and write any hierarchy, the numbers scanned in C.

A BVH skeleton becomes a :class:`Skeleton` with ``convention="bvh"``: each
JOINT a bone whose ``direction`` is its OFFSET and whose ``dofs`` are its
CHANNELS in the file's order (Xposition -> tx, Zrotation -> rz), each End
Site a channel-less bone named ``<joint>_End``.  Forward kinematics runs the
same C kernel as ASF/AMC; position channels replace the joint's OFFSET, as
Blender and MotionBuilder read them.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace

import numpy as np

from mtcore.errors import CountError, FormatError, MissingError, SequenceError, TruncatedError
from mtcore.text import format_number, format_table, parse_number, scan_table

from .._io import LINE_BREAK, PLAIN, Source, TextStyle, decode, output, read_source
from ..model.motion import Motion
from ..model.rates import rate_of_frame_time
from ..model.rig import STANDING, sampled_poses, standing_frame, standing_height
from ..model.skeleton import Bone, Root, Skeleton, canonical_hierarchy, name_problem, settle_length_unit
from ..model.units import size_up_poses
from .cut import Cut

CHANNELS = {
    "xposition": "tx",
    "yposition": "ty",
    "zposition": "tz",
    "xrotation": "rx",
    "yrotation": "ry",
    "zrotation": "rz",
}
NAMES = {dof: name.capitalize() for name, dof in CHANNELS.items()}
_BLANKS = re.compile(r"[ \t]+")
_FRAMES = re.compile(rb"^[ \t]*Frames[ \t]*:[ \t]*(\S+)[ \t]*\r?$", re.IGNORECASE | re.MULTILINE)
_FRAME_TIME = re.compile(rb"^[ \t]*Frame[ \t]+Time[ \t]*:[ \t]*(\S+)[ \t]*\r?$", re.IGNORECASE | re.MULTILINE)


def read_bvh(
    source: Source, *, unit: str | None = None, frame_rate: float | None = None, layout: bool = True
) -> Motion:
    """Read a BVH file (path or file object) into a :class:`Motion` of a BVH skeleton.

    A BVH file states no length unit: ``unit`` gives it (m, cm, mm, in, or a
    number L for inch / L); without it the unit is detected from the size of
    the rest pose, or assumed where the size tells none
    (:func:`~motiontheater.model.skeleton.settle_length_unit`;
    ``skeleton.length_source`` says which).

    Any hierarchy; channel lists of any order and count on any joint; End
    Site in any capitalisation, or none; joint names with spaces, ':' and
    '.'; CRLF; exponent notation; any run of blanks and tabs between words.
    The frame rate is the one the Frame Time was printed from
    (:func:`~motiontheater.model.rates.rate_of_frame_time`: ``0.0333333`` is
    30 Hz), or ``frame_rate`` (Hz) when given; the Frame Time's text is
    written back as found while the rate stays the one it stands for.  Bad
    input raises a :class:`~mtcore.errors.FormatError` subclass naming the
    file and line.  ``layout=False`` reads the values and the header only, not how
    the text is laid out (line endings, exponents): for a take that is looked at,
    not written back (what is written from it is laid out plainly).
    """
    return _read_source(source, unit, frame_rate, whole_frames=False, layout=layout)[0]


def read_bvh_frames(
    source: Source, *, unit: str | None = None, frame_rate: float | None = None, layout: bool = True
) -> tuple[Motion, Cut | None]:
    """:func:`read_bvh`, but of a file whose MOTION section disagrees with its header (fewer
    rows than ``Frames:`` says, more, or a last row cut short), the rows it holds whole, and how
    it disagrees (None for a whole file).  Such a motion has no file to be written back from: it
    is written anew, with a header that says its frames."""
    return _read_source(source, unit, frame_rate, whole_frames=True, layout=layout)


def _read_source(
    source: Source, unit: str | None, frame_rate: float | None, *, whole_frames: bool, layout: bool
) -> tuple[Motion, Cut | None]:
    data, name = read_source(source)
    try:
        motion, cut = _read(data, whole_frames, layout)
    except FormatError as e:
        raise e.at(name) from None
    motion = motion.replace(skeleton=settle_length_unit(_posed(motion), unit))
    motion = motion if cut is not None else motion.read_from(source)
    if frame_rate is None:
        return motion, cut
    if not 0 < frame_rate < float("inf"):
        raise ValueError(f"the frame rate must be a positive number of frames per second, got {frame_rate!r}")
    return motion.replace(frame_rate=float(frame_rate)), cut  # no longer the file's: written with its own Frame Time


def _posed(motion: Motion) -> Skeleton:
    """The skeleton, sized from the take's poses where its rest pose does not stand, tells no unit,
    or tells it only by an extent other than its height (a rig drawn along x, lying down); and
    where the rest pose does not stand, with the channels of the frame that stands best
    (``Skeleton.standing``: what retargeting plans such a rig on)."""
    skeleton = motion.skeleton
    rest = skeleton.sizing()
    stands = standing_height(skeleton.rest_positions()) > STANDING
    if (rest.unit is not None and rest.axis == rest.up and stands) or not motion.frames:
        return skeleton
    if not stands:
        skeleton = replace(skeleton, standing=standing_frame(motion))
    elif rest.unit is not None and rest.axis == rest.up:
        return skeleton
    # a rest pose that does not stand has no height: its extent along z or y is a lying or
    # T-posed body's (LAFAN's lies 2.1 m along z in cm; the same take in mm would pass for cm)
    posed = size_up_poses(sampled_poses(motion), cmu=skeleton.cmu_named)
    return replace(skeleton, posed=posed) if posed.unit is not None else skeleton


def _read(data, whole_frames: bool = False, layout: bool = True) -> tuple[Motion, Cut | None]:
    motion_at = re.search(rb"^[ \t]*MOTION[ \t]*\r?$", data, re.MULTILINE)
    if motion_at is None:
        raise MissingError("no MOTION section", data.count(b"\n") + 1)
    head = decode(data[: motion_at.start()])
    lines = [(n, line.strip()) for n, line in enumerate(LINE_BREAK.split(head), start=1) if line.strip()]
    skeleton = _hierarchy(lines)
    motion_line = data.count(b"\n", 0, motion_at.start()) + 1
    frames_match = _FRAMES.search(data, motion_at.end())
    time_match = _FRAME_TIME.search(data, motion_at.end())
    if frames_match is None or time_match is None:
        raise MissingError("the MOTION section needs 'Frames: N' and 'Frame Time: T'", motion_line)
    frames_text, frame_time = decode(frames_match.group(1)), decode(time_match.group(1))
    if not frames_text.isdigit():  # int() would take '_', signs and other scripts' digits
        raise FormatError(f"expected a whole number of frames, got {frames_text!r}", _line_of(data, frames_match))
    frames = int(frames_text)
    try:
        frame_rate = rate_of_frame_time(frame_time)
    except ValueError:
        raise FormatError(
            f"expected a positive, finite frame time in seconds, got {frame_time!r}", _line_of(data, time_match)
        ) from None
    start = max(frames_match.end(), time_match.end())
    start = data.find(b"\n", start) + 1 if data.find(b"\n", start) != -1 else len(data)
    lines_before = data.count(b"\n", 0, start)
    columns = len(skeleton.channels)
    room = (len(data) - start + 1) // max(1, 2 * columns)  # a frame takes a digit and a blank per channel
    if frames > room and frames * columns * 8 > 1 << 24:  # a header's claim is no reason to allocate much
        raise TruncatedError(
            f"the header says {frames} frames but the {len(data) - start} bytes after it hold at most {room}",
            motion_line + 1,
        )
    cut = None
    try:
        values = scan_table(data, frames, columns, start=start)
    except (TruncatedError, CountError, SequenceError) as e:
        rows, end, short = _whole_rows(data, start, columns)
        if not whole_frames or (isinstance(e, CountError) and not short):
            raise e.at(None, lines_before) from None  # a row of the wrong length amid the others: no cut
        values = scan_table(data[:end], rows, columns, start=start)
        cut = Cut(
            f"the header says {frames} frames but the file holds {rows} whole"
            + (", and a row after them cut short" if short else ""),
            lines_before + min(rows, frames) + 1,  # where it breaks off, or where the rows past its count begin
            rows,
            frames,
        )
    except FormatError as e:
        raise e.at(None, lines_before) from None
    values.flags.writeable = False
    motion = Motion(
        skeleton,
        values,
        frame_rate=frame_rate,
        first_frame=1,
        header=(f"Frame Time: {frame_time}",),
        line_order=None,
        style=TextStyle.of(data) if layout else PLAIN,
    )
    return motion, cut


def _whole_rows(data: bytes, start: int, columns: int) -> tuple[int, int, bool]:
    """The rows of a MOTION section (from ``start``) that hold a number for every channel, up
    to the first that does not: how many, the offset just past them, and whether a row after
    them is cut short (the file's last, of fewer numbers)."""
    rows, offset, short = 0, start, False
    for line in data[start:].splitlines(keepends=True):
        words = len(line.split())
        if words == columns:
            rows, offset = rows + 1, offset + len(line)
        elif words:
            short = words < columns and not data[offset + len(line) :].strip()  # the last line: cut short
            break
        else:
            offset += len(line)
    return rows, offset, short


def _line_of(data: bytes, match: re.Match) -> int:
    return data.count(b"\n", 0, match.start()) + 1


@dataclass
class _Open:
    """A joint (or End Site) whose block is being read."""

    name: str
    line: int
    offset: tuple[float, float, float] | None = None
    channels: tuple[str, ...] = ()
    end: bool = False


def _hierarchy(lines: list[tuple[int, str]]) -> Skeleton:
    if not lines or lines[0][1].upper() != "HIERARCHY":
        raise FormatError("expected HIERARCHY", lines[0][0] if lines else 1)
    bones: list[Bone] = []
    pairs: list[tuple[str, tuple[str, ...]]] = []
    root = None
    stack: list[_Open] = []  # the open joints, innermost last
    pos = 1
    while pos < len(lines):
        number, text = lines[pos]
        pos += 1
        word, rest = _BLANKS.split(text, 1) if _BLANKS.search(text) else (text, "")
        key = word.upper()
        if key in ("ROOT", "JOINT"):
            if key == "ROOT" and (stack or root is not None):
                raise FormatError("a second ROOT, or ROOT inside a joint", number)
            if key == "JOINT" and not stack:
                raise FormatError("JOINT outside the ROOT", number)
            joint = _Open(rest.strip(), number)
            if not joint.name:
                raise FormatError(f"{key} needs a name", number)
            if key == "JOINT" and (problem := name_problem(joint.name, "bvh")):
                raise FormatError(problem, number)
            if key == "JOINT" and joint.name == stack[0].name:
                raise FormatError(
                    f"joint '{joint.name}' has the name of the ROOT (line {stack[0].line}): each joint needs its own",
                    number,
                )
            pos = _expect_brace(lines, pos, number)
            if stack:
                pairs.append((stack[-1].name if len(stack) > 1 else "root", (joint.name,)))
            stack.append(joint)
        elif key == "END":
            if not stack:
                raise FormatError("End Site outside a joint", number)
            parent = stack[-1].name
            joint = _Open(f"{parent}_End", number, end=True)
            pos = _expect_brace(lines, pos, number)
            pairs.append((parent if len(stack) > 1 else "root", (joint.name,)))
            stack.append(joint)
        elif key == "OFFSET":
            if not stack:
                raise FormatError("OFFSET outside a joint", number)
            x, y, z = _numbers(rest.split(), 3, number, "OFFSET")
            stack[-1].offset = (x, y, z)
        elif key == "CHANNELS":
            if not stack or stack[-1].end:
                raise FormatError("CHANNELS outside a joint", number)
            words = rest.split()
            try:
                count = int(words[0])
            except (IndexError, ValueError):
                raise FormatError("CHANNELS needs a count and the channel names", number) from None
            names = words[1:]
            if len(names) != count:
                raise CountError(f"CHANNELS says {count} but names {len(names)}", number)
            unknown = [n for n in names if n.lower() not in CHANNELS]
            if unknown or len({n.lower() for n in names}) != len(names):
                raise FormatError(
                    f"unknown or repeated channel '{(unknown or names)[0]}'; expected "
                    "Xposition Yposition Zposition Xrotation Yrotation Zrotation",
                    number,
                )
            stack[-1].channels = tuple(CHANNELS[n.lower()] for n in names)
        elif key == "}":
            if not stack:
                raise FormatError("'}' closes nothing", number)
            joint = stack.pop()
            if joint.offset is None:
                raise MissingError(f"joint '{joint.name}' has no OFFSET", joint.line)
            if not stack:
                root = Root(order=joint.channels, axis="XYZ", position=joint.offset, name=joint.name)
            else:
                bones.append(
                    Bone(
                        name=joint.name,
                        direction=joint.offset,
                        length=float(np.linalg.norm(joint.offset)),
                        dofs=joint.channels,
                        end_site=joint.end,
                    )
                )
        else:
            raise FormatError(f"expected ROOT, JOINT, End Site, OFFSET, CHANNELS or '}}', found '{text[:40]}'", number)
    if stack:
        raise TruncatedError(f"joint '{stack[-1].name}' is not closed with '}}' before MOTION", lines[-1][0])
    if root is None:
        raise MissingError("no ROOT in the HIERARCHY", lines[0][0])
    # bones were appended as their blocks closed; the file's order is the order they opened
    opened = {child: i for i, child in enumerate(child for _, children in pairs for child in children)}
    bones.sort(key=lambda b: opened[b.name])
    return Skeleton(
        bones=tuple(bones),
        hierarchy=canonical_hierarchy(tuple(bones), pairs),
        root=root,
        units=(("angle", "deg"),),
        convention="bvh",
    )


def _expect_brace(lines, pos: int, number: int) -> int:
    if pos >= len(lines) or lines[pos][1] != "{":
        raise FormatError("expected '{' on the line after", number)
    return pos + 1


def _numbers(words: list[str], count: int, number: int, what: str) -> tuple[float, ...]:
    if len(words) != count:
        raise CountError(f"{what} takes {count} numbers, found {len(words)}", number)
    try:
        return tuple(parse_number(w) for w in words)
    except ValueError:
        raise FormatError(f"expected numbers after {what}, found '{' '.join(words)}'", number) from None


def write_bvh(motion: Motion, target: Source) -> None:
    """Write a motion of a BVH skeleton as BVH, to a path (atomically) or a binary file object;
    every number the shortest text that reads back exactly, the frame time as it was read, lines
    and exponents laid out as the file read was (``motion.style``), the last line ended with a
    line break.  A motion written back unchanged is its file's very bytes."""
    skeleton = motion.skeleton
    if skeleton.convention != "bvh":
        raise ValueError("write_bvh needs a motion of a BVH skeleton (read_bvh, or convert an ASF/AMC first)")
    if motion.unchanged() and motion.origin is not None and motion.origin.file.copy_to(target):
        return

    lines = ["HIERARCHY"]
    written: list[str] = []  # joints in the order the file declares them: its columns' order

    def joint(name: str, depth: int) -> None:
        written.append(name)
        pad = "\t" * depth
        bone = None if name == "root" else skeleton.bone(name)
        if bone is not None and bone.end_site:
            lines.extend([f"{pad}End Site", f"{pad}{{"])
        else:
            lines.extend(
                [
                    f"{pad}{'ROOT' if bone is None else 'JOINT'} {skeleton.root.name if bone is None else name}",
                    f"{pad}{{",
                ]
            )
        offset = skeleton.root.position if bone is None else bone.direction
        lines.append(f"{pad}\tOFFSET {' '.join(format_number(v) for v in offset)}")
        dofs = skeleton.dofs(name)
        if bone is None or not bone.end_site:
            lines.append(f"{pad}\tCHANNELS {len(dofs)}" + "".join(f" {NAMES[d]}" for d in dofs))
        for child in skeleton.children(name):
            joint(child, depth + 1)
        lines.append(f"{pad}}}")

    joint("root", 0)
    frame_time = next((h.split(":", 1)[1].strip() for h in motion.header if h.lower().startswith("frame time")), None)
    if frame_time is None or rate_of_frame_time(frame_time) != motion.frame_rate:
        frame_time = format_number(1.0 / motion.frame_rate)
    lines += ["MOTION", f"Frames: {motion.frames}", f"Frame Time: {frame_time}"]
    columns = [c for name in written for c in motion.columns(name)] if motion.values.shape[1] else []
    style = motion.style
    with output(target) as f:
        f.write(style.lines(lines))
        # every line ended, though the file read may have ended its last without a break:
        # python-bvh drops such a last line, and with it a frame
        format_table(motion.values[:, columns], f, **style.numbers())
