"""Twins of the scanners and formatters (scan.c, format.c): Python's float() and repr()."""

from __future__ import annotations

import math
import re

import numpy as np

LINES = re.compile(rb"\r\n|\r|\n")


def format_number(value: float) -> str:
    """repr() without a trailing ".0"; a NaN keeps its sign (-nan)."""
    if math.isnan(value):
        return "-nan" if math.copysign(1.0, value) < 0 else "nan"
    return repr(float(value)).removesuffix(".0")


def _lines(text: bytes) -> list[list[bytes]]:
    """The tokens of each line that is neither blank nor a '#' comment."""
    out = []
    for raw in LINES.split(text):
        words = raw.split()
        if words and not words[0].startswith(b"#"):
            out.append(words)
    return out


def scan_frames(text: bytes, keys, offsets, counts, channels: int, start: int = 0) -> tuple[np.ndarray, int]:
    """(values (frames, channels), first frame number or 0): float() on every token of each key
    line into its key's columns; columns no key fills are NaN.  Well-formed text only."""
    column = {k: (o, c) for k, o, c in zip(keys, offsets, counts)}
    rows, first = [], None
    for words in _lines(text[start:]):
        if len(words) == 1 and words[0].isdigit():
            first = int(words[0]) if first is None else first
            rows.append([math.nan] * channels)
            continue
        offset, count = column[words[0]]
        assert len(words) == count + 1
        rows[-1][offset : offset + count] = [float(w) for w in words[1:]]
    return np.array(rows, dtype=float).reshape(len(rows), channels), first or 0


def scan_table(text: bytes, rows: int, columns: int, start: int = 0) -> np.ndarray:
    """float() on every token of each non-blank line.  Well-formed text only."""
    lines = [raw.split() for raw in LINES.split(text[start:]) if raw.split()]
    assert len(lines) == rows and all(len(words) == columns for words in lines)
    return np.array([[float(w) for w in words] for words in lines], dtype=float).reshape(rows, columns)


def format_table(values) -> bytes:
    """A line of format_number per row, separated by blanks."""
    return b"".join(" ".join(map(format_number, row)).encode() + b"\n" for row in np.asarray(values, float).tolist())


def format_frames(values, first_frame: int, keys, offsets, counts) -> bytes:
    """Each row as its frame number, then a line per key: the key and its columns."""
    out = []
    for f, row in enumerate(np.asarray(values, float).tolist()):
        out.append(b"%d\n" % (first_frame + f))
        for key, offset, count in zip(keys, offsets, counts):
            out.append(b" ".join([key, *(format_number(v).encode() for v in row[offset : offset + count])]) + b"\n")
    return b"".join(out)


def parse_amc(data: bytes, skeleton) -> tuple[np.ndarray, int]:
    """scan_frames over an AMC file's text, its ':' header lines dropped: a column per dof of
    each joint of the skeleton, in its order."""
    body = b"\n".join(line for line in LINES.split(data) if not line.lstrip().startswith(b":"))
    names = skeleton.joint_names
    counts = [len(skeleton.dofs(joint)) for joint in names]
    offsets = np.cumsum([0, *counts[:-1]]).tolist()
    return scan_frames(body, [n.encode() for n in names], offsets, counts, sum(counts))


EXPONENT = re.compile(rb"(?<=[0-9.])[eE][+-]([0-9]+)")
FRAME_LINE = re.compile(rb"(?:^|(?<=[\r\n]))[ \t]*[0-9]+[ \t]*(\r\n|[\r\n]|\Z)")


def text_style(data: bytes) -> tuple[bytes, int, bytes]:
    """(newline, exponent digits, frame newline) by regular expressions over the first 4 MB:
    the most common line end (LF of equal counts, then CRLF); the length of the first exponent
    with a leading zero in two digits or more (at most 3), else 1 if one has a single digit,
    else 2; the ending of the first line of digits only (the newline if none or none ends it)."""
    head = data[: 1 << 22]
    crlf = head.count(b"\r\n")
    counts = {b"\n": head.count(b"\n") - crlf, b"\r\n": crlf, b"\r": head.count(b"\r") - crlf}
    newline = max(counts, key=counts.__getitem__)
    exponents = [m.group(1) for m in EXPONENT.finditer(head) if m.start() > 0]
    padded = next((len(e) for e in exponents if len(e) > 1 and e.startswith(b"0")), None)
    digits = min(padded, 3) if padded else 1 if any(len(e) == 1 for e in exponents) else 2
    frame = FRAME_LINE.search(head)
    return newline, digits, frame.group(1) if frame and frame.group(1) else newline
