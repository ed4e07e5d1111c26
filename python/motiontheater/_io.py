"""Reading sources and writing targets: paths or file objects."""

from __future__ import annotations

import contextlib
import io
import mmap
import os
import re
import tempfile
import typing
from collections.abc import Iterator
from typing import IO

Source = str | os.PathLike | IO[bytes] | IO[str]
Text = bytes | mmap.mmap  # a file's bytes, read or mapped

LINE_BREAK = re.compile(r"\r\n|\r|\n")  # as the C scanner: CRLF, lone CR and LF each end a line
PARTIAL_PREFIX = ".mt-partial-"  # files being written; a killed run may leave them, the next removes them


def read_source(source: Source) -> tuple[bytes, str | None]:
    """The bytes of a path or file object, and a name for messages."""
    if isinstance(source, (str, os.PathLike)):
        with open(source, "rb") as f:
            return f.read(), os.fspath(source)
    data = source.read()
    if isinstance(data, str):
        data = data.encode("utf-8", "surrogateescape")
    return data, getattr(source, "name", None)


@contextlib.contextmanager
def mapped_source(source: Source) -> Iterator[tuple[bytes | mmap.mmap, str | None]]:
    """Like :func:`read_source`, but a file named by path is memory-mapped, not
    copied: large takes are scanned straight from the page cache."""
    if not isinstance(source, (str, os.PathLike)) or os.path.getsize(source) == 0:
        yield read_source(source)
        return
    with open(source, "rb") as f, mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ) as mapped:
        yield mapped, os.fspath(source)


def decode(data: bytes) -> str:
    """Text of a file whose comments may hold any bytes: undecodable bytes survive
    as surrogates and are written back unchanged by :func:`encode`."""
    return data.decode("utf-8", "surrogateescape")


def encode(text: str) -> bytes:
    return text.encode("utf-8", "surrogateescape")


@contextlib.contextmanager
def output(target: Source) -> Iterator[IO[bytes]]:
    """A binary stream to write to.  For a path, the text goes to a temporary file
    beside it that replaces the path only when complete, so that a failure
    leaves no partial file."""
    if not isinstance(target, (str, os.PathLike)):
        yield typing.cast(IO[bytes], target.buffer if isinstance(target, io.TextIOWrapper) else target)
        return
    directory = os.path.dirname(os.path.abspath(target))
    fd, tmp = tempfile.mkstemp(prefix=PARTIAL_PREFIX, suffix="-" + os.path.basename(target), dir=directory)
    try:
        with os.fdopen(fd, "wb") as f:
            yield f
        os.replace(tmp, target)
    except BaseException:
        os.unlink(tmp)
        raise
