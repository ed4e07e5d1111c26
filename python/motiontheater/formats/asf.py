"""ASF (Acclaim Skeleton File): read and write, every section, any line order."""

from __future__ import annotations

import re
from dataclasses import replace

from mtcore import format_number
from mtcore.errors import CountError, DuplicateError, FormatError, MissingError, NumberError, TruncatedError
from mtcore.text import parse_number

from .._io import LINE_BREAK, Origin, Source, TextStyle, decode, output, read_source
from .._version import __version__
from ..model.skeleton import (
    BONE_DOFS,
    ROOT_DOFS,
    Bone,
    Root,
    Skeleton,
    canonical_hierarchy,
    name_problem,
    settle_length_unit,
)

_LIMIT = re.compile(r"\(\s*(\S+)\s+(\S+)\s*\)")


def _number(token: str, line: int, what: str) -> float:
    try:
        return parse_number(token)  # the grammar of every format's numbers
    except NumberError:
        raise NumberError(f"expected a number for {what}, found '{token}'", line) from None


def _numbers(tokens: list[str], count: int, line: int, what: str) -> tuple[float, ...]:
    if len(tokens) != count:
        raise CountError(f"{what} takes {count} numbers, found {len(tokens)}", line)
    return tuple(_number(t, line, what) for t in tokens)


def _axis_order(token: str, line: int) -> str:
    order = token.upper()
    if sorted(order) != ["X", "Y", "Z"]:
        raise FormatError(f"expected an axis order such as XYZ, found '{token}'", line)
    return order


class _Lines:
    """Numbered, comment-free lines of a file, split into tokens."""

    def __init__(self, text: str):
        self.items = []
        for number, raw in enumerate(LINE_BREAK.split(text), start=1):
            stripped = raw.strip()
            if stripped and not stripped.startswith("#"):
                self.items.append((number, stripped, stripped.split()))
        self.pos = 0

    def next(self):
        item = self.items[self.pos]
        self.pos += 1
        return item

    def more_in_section(self) -> bool:
        return self.pos < len(self.items) and not self.items[self.pos][1].startswith(":")


def read_asf(source: Source) -> Skeleton:
    """Read an ASF file (a path or a binary or text file object) into a :class:`Skeleton`.

    Sections and the keys inside ``:root``, bone blocks and ``:hierarchy``
    may come in any order; comments, blank lines, tabs, CRLF or mixed line
    endings and non-UTF-8 bytes are accepted.  Bad input raises a
    :class:`~mtcore.errors.FormatError` subclass naming the file and line.
    """
    data, name = read_source(source)
    try:
        skeleton = _parse(_Lines(decode(data)))
    except FormatError as e:
        raise e.at(name) from None
    skeleton = settle_length_unit(skeleton)  # a stated unit that makes the character absurdly sized is corrected
    return replace(skeleton, style=TextStyle.of(data), origin=Origin.of(source))


def _parse(lines: _Lines) -> Skeleton:
    fields: dict = {"units": (), "documentation": ()}
    sections: list[tuple[str, tuple[str, ...]]] = []
    bones: list[Bone] = []
    bone_lines: list[int] = []
    pairs: list[tuple[str, tuple[str, ...]]] = []
    root = None
    hierarchy_line = None
    while lines.pos < len(lines.items):
        number, text, tokens = lines.next()
        keyword = tokens[0].lower()
        if not keyword.startswith(":"):
            raise FormatError(f"expected a section such as :root or :bonedata, found '{text[:40]}'", number)
        rest = text[len(tokens[0]) :].strip()
        if keyword == ":version":
            fields["version"] = rest
        elif keyword == ":name":
            fields["name"] = rest
        elif keyword == ":units":
            units = []
            while lines.more_in_section():
                n, _, toks = lines.next()
                if len(toks) != 2:
                    raise CountError(f"expected 'key value' under :units, found {len(toks)} words", n)
                units.append((toks[0].lower(), toks[1]))
            fields["units"] = tuple(units)
        elif keyword == ":documentation":
            doc = []
            while lines.more_in_section():
                doc.append(lines.next()[1])
            fields["documentation"] = tuple(doc)
        elif keyword == ":root":
            root = _parse_root(lines)
        elif keyword == ":bonedata":
            for bone, line in _parse_bones(lines):
                bones.append(bone)
                bone_lines.append(line)
        elif keyword == ":hierarchy":
            hierarchy_line = number
            pairs.extend(_parse_hierarchy(lines))
        else:
            body = []
            while lines.more_in_section():
                body.append(lines.next()[1])
            sections.append((text, tuple(body)))
    if root is None:
        raise MissingError("no :root section")
    if bones and hierarchy_line is None:
        raise MissingError("no :hierarchy section (is the file truncated?)", lines.items[-1][0])
    first_line: dict[str, int] = {}
    for bone, line in zip(bones, bone_lines):
        if bone.name in first_line:
            raise DuplicateError(f"bone '{bone.name}' is defined twice (first at line {first_line[bone.name]})", line)
        first_line[bone.name] = line
    try:
        return Skeleton(
            bones=tuple(bones),
            hierarchy=canonical_hierarchy(tuple(bones), pairs),
            root=root,
            sections=tuple(sections),
            **fields,
        )
    except FormatError as e:
        e.line = e.line or hierarchy_line
        raise


def _parse_root(lines: _Lines) -> Root:
    values: dict = {}
    while lines.more_in_section():
        n, _, toks = lines.next()
        key, args = toks[0].lower(), toks[1:]
        if key == "order":
            order = tuple(a.lower() for a in args)
            if not set(order) <= set(ROOT_DOFS) or len(set(order)) != len(order):
                raise FormatError(f"root order takes distinct channels of {' '.join(d.upper() for d in ROOT_DOFS)}", n)
            values["order"] = order
        elif key == "axis":
            if len(args) != 1:
                raise CountError("root axis takes one order such as XYZ", n)
            values["axis"] = _axis_order(args[0], n)
        elif key in ("position", "orientation"):
            values[key] = _numbers(args, 3, n, f"root {key}")
        else:
            raise FormatError(f"unknown root key '{toks[0]}' (expected order, axis, position, orientation)", n)
    return Root(**values)


def _parse_bones(lines: _Lines):
    """(bone, line of its name) for each bone block."""
    while lines.more_in_section():
        n, text, toks = lines.next()
        if toks[0].lower() != "begin":
            raise FormatError(f"expected 'begin' of a bone, found '{text[:40]}'", n)
        yield _parse_bone(lines, n)


def _parse_bone(lines: _Lines, begin: int) -> tuple[Bone, int]:
    values: dict = {}
    extra = []
    limit_text, limit_line = None, begin
    while True:
        if not lines.more_in_section():
            raise TruncatedError(f"bone block that begins at line {begin} has no 'end'", lines.items[lines.pos - 1][0])
        n, text, toks = lines.next()
        key, args = toks[0].lower(), toks[1:]
        if key == "end":
            break
        if key == "id":
            if len(args) != 1 or not re.fullmatch(r"[+-]?\d+", args[0]):
                raise NumberError(f"expected a whole number after id, found '{' '.join(args)}'", n)
            values["id"] = int(args[0])
        elif key == "name":
            if len(args) != 1:
                raise CountError(f"a bone name is one word, found {len(args)}", n)
            if problem := name_problem(args[0], "asf"):
                raise FormatError(problem, n)
            values["name"], name_line = args[0], n
        elif key == "direction":
            values["direction"] = _numbers(args, 3, n, "direction")
        elif key == "length":
            values["length"] = _numbers(args, 1, n, "length")[0]
        elif key == "axis":
            if len(args) not in (3, 4):
                raise CountError(f"axis takes 3 angles and an order such as XYZ, found {len(args)} words", n)
            values["axis"] = _numbers(args[:3], 3, n, "axis")
            values["axis_order"] = _axis_order(args[3], n) if len(args) == 4 else "XYZ"
        elif key == "dof":
            dofs = tuple(a.lower() for a in args)
            bad = [d for d in dofs if d not in BONE_DOFS]
            if bad or len(set(dofs)) != len(dofs):
                raise FormatError(f"dof takes distinct channels of {' '.join(BONE_DOFS)}, found '{' '.join(args)}'", n)
            values["dofs"] = dofs
        elif key == "limits":
            limit_text, limit_line = text[len(toks[0]) :], n
            while lines.more_in_section() and lines.items[lines.pos][1].startswith("("):
                limit_text += " " + lines.next()[1]
        else:
            extra.append((key, " ".join(args)))
    if "name" not in values:
        raise MissingError(f"bone block that begins at line {begin} has no name", begin)
    if limit_text is not None:
        found = _LIMIT.findall(limit_text)
        if len(found) != len(values.get("dofs", ())):
            raise CountError(
                f"bone '{values['name']}' has {len(values.get('dofs', ()))} dofs but {len(found)} limits", limit_line
            )
        values["limits"] = tuple(
            (_number(lo, limit_line, "a limit"), _number(hi, limit_line, "a limit")) for lo, hi in found
        )
    return Bone(extra=tuple(extra), **values), name_line


def _parse_hierarchy(lines: _Lines):
    started = False
    while lines.more_in_section():
        n, _, toks = lines.next()
        key = toks[0].lower()
        if key == "begin" and len(toks) == 1:
            started = True
        elif key == "end" and len(toks) == 1:
            return
        elif not started:
            raise FormatError("expected 'begin' after :hierarchy", n)
        else:
            yield toks[0], tuple(toks[1:])
    raise TruncatedError("the :hierarchy section has no 'end'", lines.items[-1][0])


def write_asf(skeleton: Skeleton, target: Source) -> None:
    """Write a skeleton as ASF text to a path (atomically) or a binary file object.

    Numbers are written in the shortest form that reads back to the same
    float64, so reading the result gives an identical skeleton; lines end as
    the file read ended them.  A skeleton equal to its file's is written as
    the file's very bytes.
    """
    origin = skeleton.origin
    if origin is not None and origin.intact() and read_asf(origin.path) == skeleton and origin.copy_to(target):
        return
    with output(target) as f:
        f.write(skeleton.style.lines(list(_asf_lines(skeleton))))


def _num(*values: float) -> str:
    return " ".join(format_number(v) for v in values)


def _asf_lines(s: Skeleton):
    yield f"# ASF written by motiontheater {__version__}"
    yield f":version {s.version}"
    yield f":name {s.name}"
    yield ":units"
    yield from (f"  {key} {value}" for key, value in s.units)
    yield ":documentation"
    yield from (f"   {line}" for line in s.documentation)
    yield ":root"
    yield f"   order {' '.join(d.upper() for d in s.root.order)}"
    yield f"   axis {s.root.axis}"
    yield f"   position {_num(*s.root.position)}"
    yield f"   orientation {_num(*s.root.orientation)}"
    yield ":bonedata"
    for bone in s.bones:
        yield "  begin"
        if bone.id is not None:  # an id the file did not give is not made up
            yield f"     id {bone.id}"
        yield f"     name {bone.name}"
        yield f"     direction {_num(*bone.direction)}"
        yield f"     length {_num(bone.length)}"
        yield f"     axis {_num(*bone.axis)} {bone.axis_order}"
        if bone.dofs:
            yield f"     dof {' '.join(bone.dofs)}"
        # other keys before the limits: a key line that looks like "(lo hi)" must not follow them
        yield from (f"     {key} {value}".rstrip() for key, value in bone.extra)
        for j, (lo, hi) in enumerate(bone.limits):
            yield f"     {'limits' if j == 0 else '      '} ({_num(lo)} {_num(hi)})"
        yield "  end"
    yield ":hierarchy"
    yield "  begin"
    yield from (f"    {parent} {' '.join(children)}" for parent, children in s.hierarchy)
    yield "  end"
    for keyword, body in s.sections:
        yield keyword
        yield from (f"  {line}" for line in body)
