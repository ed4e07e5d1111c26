"""Frame text (the body of an AMC file) to and from arrays, in C.

Frame text is a sequence of frames, each a line holding its frame number
followed by key lines ``key v1 v2 ...``; see ``mtcore.h``.  Keys are opaque
byte strings here: the caller (motiontheater's AMC reader) maps bones to keys
and columns.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from ._mtcore import ffi, lib
from ._status import check

__all__ = ["scan_frames", "format_frames", "format_number"]

_FORMAT_CHUNK = 2048  # frames per C call when writing: bounds the text buffer


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


def _line_text(text: bytes, offset: int) -> str:
    end = len(text)
    for stop in (b"\n", b"\r"):
        found = text.find(stop, offset)
        if found != -1:
            end = min(end, found)
    return text[offset:end].decode("utf-8", "replace").strip()


def scan_frames(
    text: bytes,
    keys: Sequence[bytes],
    offsets: Sequence[int],
    counts: Sequence[int],
    channels: int,
    *,
    start: int = 0,
    noun: str = "key",
) -> tuple[np.ndarray, int]:
    """Scan the frame text ``text[start:]`` into a new (frames, channels) float64 array.

    Returns the array and the number of the first frame (0 when there are
    none).  Columns that no key fills are NaN.  Raises a
    :class:`~mtcore.errors.FormatError` subclass whose ``line`` counts from 1 at
    ``text[start]`` and whose message calls keys ``noun``.
    """
    table = _KeyTable(keys, offsets, counts, channels)
    if not 0 <= start <= len(text):
        raise ValueError(f"start must be within the text's {len(text)} bytes, got {start}")
    size = len(text) - start
    # A frame takes at least a digit and, for each key with numbers, the key and
    # a digit and a blank per number.  Pages past the frames found are never
    # touched, so the excess costs address space, not memory.
    least = 1 + sum(len(k) + 2 * c for k, c in zip(keys, counts) if c > 0)
    capacity = size // least + 1
    values = np.empty((capacity, channels))
    report = ffi.new("struct mt_scan_report *")
    with ffi.from_buffer(text) as c_text:
        with ffi.from_buffer("double[]", values) as c_values:
            status = lib.mt_scan_frames(
                c_text + start, size, table.c_keys, table.c_lens, table.c_offsets, table.c_counts,
                table.n, c_values, capacity, channels, report,
            )
    check(status, "mt_scan_frames", _describer(text, start, table, report, noun))
    values.resize((report.frames, channels), refcheck=False)  # in place: realloc
    covered = np.zeros(channels, bool)
    for offset, count in zip(offsets, counts):
        covered[offset:offset + count] = True
    values[:, ~covered] = np.nan
    return values, int(report.first_frame)


def _describer(text: bytes, start: int, table: _KeyTable, report, noun: str) -> Callable[[int], tuple[str, int, bool]]:
    def describe(status: int) -> tuple[str, int, bool]:
        line = _line_text(text, start + report.offset)
        key = table.keys[report.key].decode("utf-8", "replace") if report.key >= 0 else None
        frame = report.first_frame + report.frames - 1
        rest = text[start + report.offset:]
        # An error in a last line that has no line break: the file was cut there.
        truncated = not rest.strip() or not any(c in rest for c in b"\r\n")
        if status == lib.MT_ESYNTAX:
            tokens = line.split()
            token = tokens[report.found + 1] if report.found + 1 < len(tokens) else ""
            reason = f"expected a number as value {report.found + 1} of {noun} '{key}', found '{token}'"
        elif status == lib.MT_ECOUNT:
            reason = f"{noun} '{key}' takes {report.expected} value(s), found {report.found}: '{line[:80]}'"
        elif status == lib.MT_EUNKNOWN:
            token = line.split()[0] if line else ""
            reason = f"unknown {noun} '{token}'; expected one of: " + ", ".join(
                k.decode("utf-8", "replace") for k in table.keys[:8]
            ) + (", ..." if len(table.keys) > 8 else "")
        elif status == lib.MT_EDUPLICATE:
            reason = f"{noun} '{key}' appears twice in frame {frame}"
        elif status == lib.MT_EMISSING:
            reason = f"frame {frame} has no line for {noun} '{key}'"
        elif report.expected == -1:
            reason = f"expected a frame number, found '{line[:80]}'"
        else:
            reason = f"frame number {report.found} out of sequence: expected {report.expected}"
        if truncated:
            reason += " (the file ends there: truncated?)"
        return reason, int(report.line), truncated

    return describe


def format_frames(
    values: np.ndarray,
    first_frame: int,
    keys: Sequence[bytes],
    offsets: Sequence[int],
    counts: Sequence[int],
    write: Callable[[bytes], object],
) -> None:
    """Write (frames, channels) values as frame text through ``write``, in chunks.

    Key lines come in the order of ``keys``; every number is the shortest text
    that reads back to exactly the same float64.
    """
    values = np.ascontiguousarray(values, dtype=np.float64)
    if values.ndim != 2:
        raise ValueError(f"values must be (frames, channels), got shape {values.shape}")
    frames, channels = values.shape
    table = _KeyTable(keys, offsets, counts, channels)
    chunk = max(1, min(frames, _FORMAT_CHUNK))
    buf = bytearray(lib.mt_format_bound(chunk, table.c_lens, table.c_counts, table.n))
    written = ffi.new("size_t *")
    with ffi.from_buffer("double[]", values) as c_values, ffi.from_buffer(buf) as c_buf:
        for f0 in range(0, frames, chunk):
            n = min(chunk, frames - f0)
            status = lib.mt_format_frames(
                c_values + f0 * channels, n, channels, first_frame + f0, table.c_keys, table.c_lens,
                table.c_offsets, table.c_counts, table.n, c_buf, len(buf), written,
            )
            check(status, "mt_format_frames")
            write(bytes(memoryview(buf)[: written[0]]))


def format_number(value: float) -> str:
    """The shortest text that reads back as exactly ``value`` (``%g`` style: 17.8693, 1e-05, 3)."""
    buf = ffi.new("char[]", lib.MT_NUMBER_MAX)
    return ffi.unpack(buf, lib.mt_format_double(float(value), buf)).decode("ascii")
