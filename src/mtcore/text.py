"""Numbers and frame text (the body of an AMC file) to and from arrays, in C.

Frame text is a sequence of frames, each a line holding its frame number
followed by key lines ``key v1 v2 ...``; see ``mtcore.h``.  Keys are opaque
byte strings here: the caller (motiontheater's AMC reader) maps bones to keys
and columns.

Every number, in every format, follows one grammar: an optional sign, digits
with an optional '.', an optional exponent (``e``/``E``, optional sign,
digits); or ``inf``, ``infinity``, ``nan`` in any case with an optional sign.
It reads as the float64 nearest to it, exactly what ``float()`` gives, for any
count of digits; no hexadecimal, ``_`` or ``nan(...)``.  Reading and writing
never depend on the C locale.
"""

from __future__ import annotations

import errno
import functools
import itertools
import mmap
import operator
import re
from collections.abc import Callable, Sequence
from typing import IO, Any, NamedTuple

import numpy as np

from . import _checks
from ._cdata import c_array
from ._mtcore import ffi, lib
from ._parallel import run_all, thread_count
from ._status import check
from .errors import NumberError, SequenceError

check(lib.mt_guard_install(), "mt_guard_install")  # scanning a mapped file that shrinks: an error, not a crash

Text = bytes | mmap.mmap  # text to scan: read into memory, or mapped from its file

__all__ = [
    "FRAME_MAX",
    "TextLayout",
    "format_frames",
    "format_number",
    "format_table",
    "frame_line",
    "line_breaks",
    "number_code",
    "number_codes",
    "parse_number",
    "scan_frames",
    "scan_table",
    "text_style",
]

FRAME_MAX: int = lib.MT_FRAME_MAX
"""The largest frame number that frame text can hold (18 digits); the smallest is 0."""

_FORMAT_CHUNK = 256  # frames per C call when writing: a text buffer that stays in cache
_NEWLINES = {b"\n": lib.MT_NEWLINE_LF, b"\r\n": lib.MT_NEWLINE_CRLF, b"\r": lib.MT_NEWLINE_CR}
_DECIMAL = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")  # the grammar's decimals
_GRAMMAR = "a number (optional sign, digits with an optional '.' and exponent, as 17.8693 or -1.2e-05; or inf, nan)"
# the codes that write the shortest texts (enum mt_number_code), widest first
_NUMBER_CODES = {
    "avx512": lib.MT_NUMBER_CODE_AVX512,
    "avx2": lib.MT_NUMBER_CODE_AVX2,
    "portable": lib.MT_NUMBER_CODE_PORTABLE,
}


def number_code() -> str:
    """The name of the code that writes the shortest texts of numbers on this processor, the one
    ``code="best"`` stands for: ``"avx512"`` or ``"avx2"`` (code written for the vector registers of
    x86-64 processors of those levels), else ``"portable"``.  Every code writes the same bytes."""
    best = lib.mt_number_code()
    return next(name for name, code in _NUMBER_CODES.items() if code == best)


def number_codes() -> tuple[str, ...]:
    """The names of the codes that this processor runs for the shortest texts, widest first (the
    first is :func:`number_code`); any of them, or ``"best"``, is a ``code=`` of the writers."""
    return tuple(name for name, code in _NUMBER_CODES.items() if lib.mt_number_code_runs(code))


def _number_code(code: str) -> int:
    """The C code of a name of ``code=``, checked against what this processor runs."""
    if code == "best":
        return lib.MT_NUMBER_CODE_BEST
    if code not in _NUMBER_CODES:
        raise ValueError(f"code must be 'best' or one of {sorted(_NUMBER_CODES)}, got {code!r}")
    if not lib.mt_number_code_runs(_NUMBER_CODES[code]):
        raise ValueError(f"code {code!r} does not run on this processor, which runs {', '.join(number_codes())}")
    return _NUMBER_CODES[code]


def _style(digits: int | None, exponent_digits: int, newline: bytes = b"\n", frame_newline: bytes | None = None):
    """The C style of numbers and lines, checked: see format_frames."""
    if digits is not None:
        digits = _checks.integer(digits, "digits", 1, 17, note=" (or None: the shortest exact text)")
    exponent_digits = _checks.integer(exponent_digits, "exponent_digits", 1, 3)
    frame_newline = newline if frame_newline is None else frame_newline
    _checks.choice(newline, "newline", _NEWLINES)
    _checks.choice(frame_newline, "frame_newline", _NEWLINES)
    return ffi.new(
        "struct mt_format_style *", [digits or 0, exponent_digits, _NEWLINES[newline], _NEWLINES[frame_newline]]
    )


class _KeyTable:
    """Keys, column offsets and counts as C arrays (kept alive with this object)."""

    def __init__(self, keys: Sequence[bytes], offsets: Sequence[int], counts: Sequence[int], channels: int):
        if not (len(keys) == len(offsets) == len(counts)):
            raise ValueError("keys, offsets and counts must have the same length")
        for key, offset, count in zip(keys, offsets, counts):
            if not key or any(c in key for c in b" \t\r\n"):
                raise ValueError(f"keys must be non-empty and free of blanks, got {key!r}")
            if offset < 0 or count < 0 or offset + count > channels:
                raise ValueError(f"columns {offset}..{offset + count - 1} of key {key!r} exceed {channels} channels")
        self.keys = list(keys)
        self.counts = list(counts)
        self._strings = [ffi.new("char[]", k) for k in keys]
        self.c_keys = ffi.new("const char *[]", self._strings)
        self.c_lens = ffi.new("size_t[]", [len(k) for k in keys])
        self.c_offsets = ffi.new("size_t[]", list(offsets))
        self.c_counts = ffi.new("size_t[]", list(counts))
        self.n = len(keys)
        # A frame takes at least a digit and, for each key with numbers, the key and a digit and a
        # blank per number: how many frames a text can hold at most.
        self.least_frame_bytes = 1 + sum(len(k) + 2 * c for k, c in zip(keys, counts) if c > 0)
        covered = np.zeros(channels, bool)
        for offset, count in zip(offsets, counts):
            covered[offset : offset + count] = True
        self.uncovered = np.flatnonzero(~covered)  # columns no key fills


@functools.lru_cache(maxsize=64)
def _key_table(keys: tuple[bytes, ...], offsets: tuple[int, ...], counts: tuple[int, ...], channels: int) -> _KeyTable:
    """The key table of a layout, made once: a batch reads and writes thousands of takes of a few."""
    return _KeyTable(keys, offsets, counts, channels)


def _line_at(text: Text, offset: int) -> tuple[str, bool]:
    """The line that begins at ``offset`` (its first 4 KB), and whether a line break ends it
    (a last line without one is where a file was cut)."""
    window = copy_text(text, offset, offset + 4096)
    breaks = [i for i in (window.find(b"\n"), window.find(b"\r")) if i != -1]
    line = window[: min(breaks)] if breaks else window
    ended = bool(breaks) or (offset + len(window) < len(text) and _break_after(text, offset + len(window)))
    return line.decode("utf-8", "replace").strip(), ended


def _blank_to_end(text: Text, offset: int) -> bool:
    """Whether nothing but blanks and line breaks follows ``offset`` (read a window at a time)."""
    while offset < len(text):
        window = copy_text(text, offset, offset + _WINDOW)
        if window.strip():
            return False
        offset += len(window)
    return True


def _break_after(text: Text, offset: int) -> bool:
    """Whether a line break follows ``offset`` anywhere in the text (read a window at a time)."""
    while offset < len(text):
        window = copy_text(text, offset, offset + _WINDOW)
        if b"\n" in window or b"\r" in window:
            return True
        offset += len(window)
    return False


def scan_frames(
    text: Text,
    keys: Sequence[bytes],
    offsets: Sequence[int],
    counts: Sequence[int],
    channels: int,
    *,
    start: int = 0,
    noun: str = "key",
    workers: int | None = None,
) -> tuple[np.ndarray, int]:
    """Scan the frame text ``text[start:]`` into a new (frames, channels) float64 array.

    Returns the array and the number of the first frame (0 when there are
    none).  Columns that no key fills are NaN.  Raises a
    :class:`~mtcore.errors.FormatError` subclass whose ``line`` counts from 1 at
    ``text[start]`` and whose message calls keys ``noun``.  Texts of several
    megabytes are cut at frame lines and scanned on all cores (``workers``
    as for the filters: None for automatic, 1 for the calling thread only).
    """
    table = _key_table(tuple(keys), tuple(offsets), tuple(counts), channels)
    if not 0 <= start <= len(text):
        raise ValueError(f"start must be within the text's {len(text)} bytes, got {start}")
    # Pages past the frames found are never touched, so room for the most frames a text can hold
    # costs address space, not memory.
    pieces = _pieces(text, start, _piece_count(workers, len(text) - start))
    capacities = [(stop - begin) // table.least_frame_bytes + 1 for begin, stop in pieces]
    bases = np.cumsum([0, *capacities]).tolist()
    values = np.empty((bases[-1], channels))
    reports: list[Any] = [ffi.new("struct mt_scan_report *") for _ in pieces]  # structs: fields by name
    with ffi.from_buffer(text) as c_text, c_array(values) as c_values:

        def piece(i: int):
            begin, stop = pieces[i]
            return lambda: lib.mt_scan_frames(
                c_text + begin,
                stop - begin,
                table.c_keys,
                table.c_lens,
                table.c_offsets,
                table.c_counts,
                table.n,
                c_values + bases[i] * channels,
                capacities[i],
                channels,
                reports[i],
            )

        statuses = run_all([piece(i) for i in range(len(pieces))])
    frames, first = 0, 0
    for (begin, _), base, report, status in zip(pieces, bases, reports, statuses):
        # the piece's first frame number comes before anything else wrong in it, as in one piece
        if frames and report.frames and report.first_frame != first + frames:
            raise SequenceError(
                f"frame number {report.first_frame} out of sequence: expected {first + frames}",
                line_breaks(text, start, begin) + 1,
            )
        check(status, "mt_scan_frames", _describer(text, start, begin, table, report, noun))
        if not frames:
            first = report.first_frame
        if base != frames:
            values[frames : frames + report.frames] = values[base : base + report.frames]
        frames += report.frames
    values.resize((frames, channels), refcheck=False)  # in place: realloc
    if len(table.uncovered):
        values[:, table.uncovered] = np.nan
    return values, int(first) if frames else 0


_PIECE_BYTES = 1 << 20  # below this a text is scanned in one piece
_FRAME_LINE = re.compile(rb"(?:^|(?<=[\r\n]))[ \t]*\d+[ \t]*(?:\r\n|[\r\n]|\Z)")


def copy_text(text: Text, begin: int = 0, end: int | None = None) -> bytes:
    """``text[begin:end]`` as bytes.  From a mapped file the bytes come through a guarded copy, so a
    file shrunk by another program meanwhile is an OSError here, not a crash (SIGBUS)."""
    end = len(text) if end is None else min(end, len(text))
    if not isinstance(text, mmap.mmap):
        return bytes(text[begin:end])
    out = bytearray(max(0, end - begin))
    if out:
        with ffi.from_buffer(text) as source, ffi.from_buffer(out) as target:
            check(lib.mt_copy_mapped(source + begin, len(out), target), "mt_copy_mapped")
    return bytes(out)


_WINDOW = 1 << 16  # bytes of a mapped file that Python looks at a time


def frame_line(text: Text, start: int = 0, end: int | None = None, *, last: bool = False) -> int:
    """The offset of the first (with ``last``, the last) line that begins within ``text[start:end]``
    and holds only a frame number, or -1.  Lines end in LF, CRLF or CR.  A mapped file is read a
    window at a time through :func:`copy_text`."""
    end = len(text) if end is None else end
    if isinstance(text, mmap.mmap) and not last:
        window = _WINDOW
        while True:  # the byte before start too: whether a line begins at start
            low = max(0, start - 1)
            piece = copy_text(text, low, min(end, start + window))
            found = frame_line(piece, start - low, len(piece))
            if found != -1 or start + window >= end:
                return -1 if found == -1 else low + found
            window *= 4
    if isinstance(text, mmap.mmap):
        low = max(start, end - 16 * _WINDOW)
        found = frame_line(copy_text(text, low, end), 0 if low == start else 1, last=True)
        return found + low if found != -1 else frame_line(text, start, low, last=True) if low > start else -1
    if not last:
        match = _FRAME_LINE.search(text, start, end)
        return -1 if match is None else match.start()
    window = 4096  # a frame is a few dozen lines: look back a window at a time, not over all of text
    while True:
        low = max(start, _line_start(text, max(start, end - window)))
        hits = [m.start() for m in _FRAME_LINE.finditer(text, low, end)]
        if hits or low == start:
            return hits[-1] if hits else -1
        window *= 2


def _line_start(text: Text, offset: int) -> int:
    """The offset of the start of the line holding ``offset``."""
    return max(text.rfind(b"\n", 0, offset), text.rfind(b"\r", 0, offset)) + 1


def _piece_count(workers: int | None, size: int) -> int:
    return max(1, min(thread_count(workers, True), size // _PIECE_BYTES))


def _pieces(text: Text, start: int, count: int) -> list[tuple[int, int]]:
    """Byte ranges that together cover text[start:], each beginning at a frame line."""
    bounds = [start]
    for i in range(1, count):
        target = start + (len(text) - start) * i // count
        found = frame_line(text, max(target, bounds[-1]) + 1)
        if found == -1:
            break
        bounds.append(found)
    bounds.append(len(text))
    return list(itertools.pairwise(bounds))


def line_breaks(text: Text, begin: int = 0, end: int | None = None) -> int:
    """The number of line ends (LF, CRLF or CR) in ``text[begin:end]``."""
    part = copy_text(text, begin, end)
    return part.count(b"\n") + part.count(b"\r") - part.count(b"\r\n")


def _describer(
    text: Text, start: int, begin: int, table: _KeyTable, report, noun: str
) -> Callable[[int], tuple[str, int, bool]]:
    """What went wrong in the piece of text that starts at ``begin`` (line numbers from ``start``)."""

    def describe(status: int) -> tuple[str, int, bool]:
        line, ended = _line_at(text, begin + report.offset)
        key = table.keys[report.key].decode("utf-8", "replace") if report.key >= 0 else None
        frame = report.first_frame + report.frames - 1
        # An error in a last line that has no line break, or with nothing but blanks after it: the
        # file was cut there.
        truncated = not ended or _blank_to_end(text, begin + report.offset)
        if status == lib.MT_ESYNTAX:
            tokens = line.split()
            token = tokens[report.found + 1] if report.found + 1 < len(tokens) else ""
            reason = f"expected a number as value {report.found + 1} of {noun} '{key}', found '{token}'"
        elif status == lib.MT_ECOUNT:
            reason = f"{noun} '{key}' takes {report.expected} value(s), found {report.found}: '{line[:80]}'"
        elif status == lib.MT_EUNKNOWN:
            token = line.split()[0] if line else ""
            reason = (
                f"unknown {noun} '{token}'; expected one of: "
                + ", ".join(k.decode("utf-8", "replace") for k in table.keys[:8])
                + (", ..." if len(table.keys) > 8 else "")
            )
        elif status == lib.MT_EDUPLICATE:
            reason = f"{noun} '{key}' appears twice in frame {frame}"
        elif status == lib.MT_EMISSING:
            reason = f"frame {frame} has no line for {noun} '{key}'"
        elif status == lib.MT_EFRAMERANGE:
            reason = f"frame number '{line.split()[0]}' is past the largest, {FRAME_MAX}"
        elif report.expected == -1:
            reason = f"expected a frame number, found '{line[:80]}'"
        else:
            reason = f"frame number {report.found} out of sequence: expected {report.expected}"
        if truncated:
            reason += " (the file ends there: truncated?)"
        return reason, line_breaks(text, start, begin) + int(report.line), truncated

    return describe


def _sink(out: IO[bytes] | Callable[[bytes], object]) -> Callable[[np.ndarray], object]:
    """How a chunk of text in the writers' buffer reaches ``out``: a file writes the buffer itself
    before it is used again (a copy of each chunk cost a tenth of the writing); a function is given
    bytes of its own, which it may keep."""
    if callable(out):
        return lambda chunk: out(chunk.tobytes())
    file = out

    def write(chunk: np.ndarray) -> None:
        view = chunk.data
        while view:  # an unbuffered file may take a part at a time
            taken = file.write(view)
            if taken is None:
                raise BlockingIOError(errno.EAGAIN, "the file takes no more text now (non-blocking)")
            view = view[taken:]

    return write


def format_frames(
    values: np.ndarray,
    first_frame: int,
    keys: Sequence[bytes],
    offsets: Sequence[int],
    counts: Sequence[int],
    out: IO[bytes] | Callable[[bytes], object],
    *,
    digits: int | None = None,
    exponent_digits: int = 2,
    newline: bytes = b"\n",
    frame_newline: bytes | None = None,
    code: str = "best",
) -> None:
    """Write (frames, channels) values as frame text to ``out``, in chunks: a binary file (as
    ``open(path, "wb")`` gives), or a function given each chunk as bytes.

    Key lines come in the order of ``keys``; frames are numbered from
    ``first_frame`` (all numbers must lie in 0 .. FRAME_MAX, to be read back).
    Every number is the shortest text that reads back to exactly the same
    float64 (the digits of ``repr``), or with ``digits=N`` (1 to 17) the value
    correctly rounded to N significant digits, as C's ``%.Ng``: smaller files,
    inexact.  ``exponent_digits`` is the fewest digits of an exponent (2:
    ``1e-05``; 3: ``1e-005`` as HDM05 writes), ``newline`` the line ending
    (``b"\\n"``, ``b"\\r\\n"`` or ``b"\\r"``); :func:`text_style` finds both in a file.
    ``code`` names the code that writes the shortest texts (:func:`number_codes`): the same
    bytes from each; other than ``"best"`` for tests and benchmarks that compare them.
    """
    style = _style(digits, exponent_digits, newline, frame_newline)
    c_code = _number_code(code)
    values = np.ascontiguousarray(values, dtype=np.float64)
    if values.ndim != 2:
        raise ValueError(f"values must be (frames, channels), got shape {values.shape}")
    frames, channels = values.shape
    first_frame = operator.index(first_frame)
    if not 0 <= first_frame <= FRAME_MAX - max(frames - 1, 0):
        raise ValueError(
            f"frame numbers {first_frame} .. {first_frame + frames - 1} cannot be written: frame text "
            f"holds 0 .. {FRAME_MAX}"
        )
    table = _key_table(tuple(keys), tuple(offsets), tuple(counts), channels)
    chunk = max(1, min(frames, _FORMAT_CHUNK))
    buf = np.empty(lib.mt_format_bound(chunk, table.c_lens, table.c_counts, table.n, style), np.uint8)  # not zeroed
    written = ffi.new("size_t *")
    write = _sink(out)
    with c_array(values) as c_values, c_array(buf, "char[]") as c_buf:
        for f0 in range(0, frames, chunk):
            n = min(chunk, frames - f0)
            status = lib.mt_format_frames(
                c_values + f0 * channels,
                n,
                channels,
                first_frame + f0,
                table.c_keys,
                table.c_lens,
                table.c_offsets,
                table.c_counts,
                table.n,
                style,
                c_code,
                c_buf,
                len(buf),
                written,
            )
            check(status, "mt_format_frames")
            write(buf[: written[0]])


def scan_table(text: bytes, rows: int, columns: int, *, start: int = 0, workers: int | None = None) -> np.ndarray:
    """Scan ``text[start:]``, lines of exactly ``columns`` numbers, into a new (rows, columns)
    float64 array (a BVH MOTION section).  A FormatError subclass names the line, counted
    from 1 at ``text[start]``, and what was expected.  Large tables are scanned on all cores
    when their line breaks show where every piece's rows begin (``workers`` as for the filters)."""
    if rows < 0 or columns < 0:
        raise ValueError(f"rows and columns must not be negative, got {rows}, {columns}")
    if not 0 <= start <= len(text):
        raise ValueError(f"start must be within the text's {len(text)} bytes, got {start}")
    values = np.empty((rows, columns))
    pieces = _table_pieces(text, start, rows, _piece_count(workers, len(text) - start))
    reports: list[Any] = [ffi.new("struct mt_scan_report *") for _ in pieces]  # structs: fields by name
    with ffi.from_buffer(text) as c_text, c_array(values) as c_values:

        def piece(i: int):
            begin, stop, first_row, count = pieces[i]
            return lambda: lib.mt_scan_table(
                c_text + begin, stop - begin, count, columns, c_values + first_row * columns, reports[i]
            )

        statuses = run_all([piece(i) for i in range(len(pieces))])
    for (begin, _, _, _), report, status in zip(pieces, reports, statuses):
        if status == lib.MT_OK:
            continue
        lines_before = line_breaks(text, start, begin)

        def describe(code: int, report=report, begin=begin, lines_before=lines_before) -> tuple[str, int, bool]:
            line, at = _line_at(text, begin + report.offset)[0], lines_before + report.line
            if code == lib.MT_ESYNTAX:
                tokens = line.split()
                token = tokens[report.found] if report.found < len(tokens) else ""
                return f"expected a number as value {report.found + 1} of the frame, found '{token}'", at, False
            if code == lib.MT_ECOUNT:
                return (
                    f"a frame takes {report.expected} values (the channels declared), found {report.found}",
                    at,
                    False,
                )
            held = report.frames + sum(p[3] for p in pieces if p[0] < begin)
            return f"the header says {rows} frames but the data holds {held} (truncated?)", at, True

        if status == lib.MT_ERANGE:
            raise SequenceError(f"the header says {rows} frames but the data holds more", lines_before + report.line)
        check(status, "mt_scan_table", describe)
    return values


def _table_pieces(text: bytes, start: int, rows: int, count: int) -> list[tuple[int, int, int, int]]:
    """(begin, end, first row, rows) of pieces that together cover text[start:].  Several
    pieces only where every line holds a row (no blank lines, LF or CRLF endings, as writers
    write), so that each piece's rows are known from its line breaks; else one piece."""
    whole = [(start, len(text), 0, rows)]
    if count < 2:
        return whole
    size = len(text) - start
    ends_open = not text.endswith(b"\n")
    crs = text.count(b"\r", start)
    if (
        text.count(b"\n", start) + ends_open != rows
        or text.find(b"\n\n", start) != -1
        or text.find(b"\n\r\n", start) != -1
        or (crs and crs != text.count(b"\r\n", start))
    ):
        return whole
    bounds, first = [start], [0]
    for i in range(1, count):
        cut = text.find(b"\n", start + size * i // count)
        if cut == -1 or cut + 1 >= len(text):
            break
        first.append(first[-1] + text.count(b"\n", bounds[-1], cut + 1))
        bounds.append(cut + 1)
    bounds.append(len(text))
    first.append(rows)
    return [(bounds[i], bounds[i + 1], first[i], first[i + 1] - first[i]) for i in range(len(bounds) - 1)]


def format_table(
    values: np.ndarray,
    out: IO[bytes] | Callable[[bytes], object],
    *,
    digits: int | None = None,
    exponent_digits: int = 2,
    newline: bytes = b"\n",
    code: str = "best",
) -> None:
    """Write (rows, columns) values as lines of numbers separated by a blank to ``out``, in chunks;
    ``out``, numbers, lines and ``code`` as for :func:`format_frames`."""
    style = _style(digits, exponent_digits, newline)
    c_code = _number_code(code)
    values = np.ascontiguousarray(values, dtype=np.float64)
    if values.ndim != 2:
        raise ValueError(f"values must be (rows, columns), got shape {values.shape}")
    rows, columns = values.shape
    chunk = max(1, min(rows, _FORMAT_CHUNK))
    buf = np.empty(lib.mt_format_table_bound(chunk, columns, style), np.uint8)  # not zeroed
    written = ffi.new("size_t *")
    write = _sink(out)
    with c_array(values) as c_values, c_array(buf, "char[]") as c_buf:
        for r0 in range(0, rows, chunk):
            n = min(chunk, rows - r0)
            status = lib.mt_format_table(c_values + r0 * columns, n, columns, style, c_code, c_buf, len(buf), written)
            check(status, "mt_format_table")
            write(buf[: written[0]])


def format_number(value: float, *, digits: int | None = None, exponent_digits: int = 2) -> str:
    """The text of one number, as :func:`format_frames` writes it: by default the shortest
    that reads back as exactly ``value`` (17.8693, 1e-05, 3, -0, inf, nan)."""
    buf = ffi.new("char[]", lib.MT_NUMBER_MAX)
    written = ffi.new("size_t *")
    check(lib.mt_format_double(float(value), _style(digits, exponent_digits), buf, written), "mt_format_double")
    return bytes(ffi.buffer(buf, written[0])).decode("ascii")


def parse_number(token: str | bytes) -> float:
    """The float64 of one number token (no blanks around it), by the grammar of every format:
    equal to ``float(token)`` wherever this accepts the token.

    Raises :class:`~mtcore.errors.NumberError` (a ValueError) saying what was expected, for
    anything else: hexadecimal, ``1_0``, ``nan(...)``, blanks, the empty string.  Bytes are read
    by the C parser of the scanners; text in the usual decimal forms by ``float()``, the same value.
    """
    if isinstance(token, str) and _DECIMAL.fullmatch(token):
        return float(token)  # the grammar's value, as the C parser's (headers parse thousands of these)
    data = token.encode("ascii", "replace") if isinstance(token, str) else bytes(token)
    value = ffi.new("double *")
    with ffi.from_buffer(data) as c_data:
        status = lib.mt_parse_number(c_data, len(data), value)
    if status != lib.MT_OK:
        shown = token if isinstance(token, str) else data.decode("ascii", "replace")
        raise NumberError(f"expected {_GRAMMAR}, found '{shown}'")
    return value[0]


_STYLE_SAMPLE = 1 << 22  # bytes of a file that text_style looks at
_NEWLINE_BYTES = {code: ending for ending, code in _NEWLINES.items()}


class TextLayout(NamedTuple):
    """How a file's text is laid out (see :func:`text_style`)."""

    newline: bytes
    exponent_digits: int
    frame_newline: bytes


def text_style(data: Text) -> TextLayout:
    """The line ending, the fewest exponent digits of the numbers and the ending of the frame
    lines of a file's text, for writing it back alike (the options of :func:`format_frames`).

    The newline is the one most lines of the first 4 MB end in (``b"\\r\\n"``, ``b"\\n"``
    or ``b"\\r"``; ``b"\\n"`` where there is none, and of equal counts the first of LF,
    CRLF, CR).  Exponent digits: 3 where an exponent there is written with a leading zero in
    three digits (``1.23246e-013``), 1 where one has a single digit (``1e-5``), else 2
    (Python and C on Linux: ``1e-05``).  The frame newline ends the first line that holds
    only a frame number (HDM05 ends those in LF and every other line in CRLF); the newline
    where there is none.  In C, straight passes over the bytes; a mapped file is read under the guard.
    """
    style: Any = ffi.new("struct mt_text_style *")  # a struct: fields by name
    size = min(len(data), _STYLE_SAMPLE)
    with ffi.from_buffer(data) as c_data:
        check(lib.mt_text_style(c_data, size, style), "mt_text_style")
    counts = {b"\n": style.lf, b"\r\n": style.crlf, b"\r": style.cr}
    newline = max(counts, key=counts.__getitem__)
    frame_newline = _NEWLINE_BYTES.get(style.frame_newline, newline)
    return TextLayout(newline, style.exponent_digits, frame_newline)
