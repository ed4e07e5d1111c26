"""Reading sources and writing targets: paths or file objects."""

from __future__ import annotations

import contextlib
import errno
import io
import mmap
import os
import re
import secrets
import shutil
import stat
import typing
from collections.abc import Iterator
from dataclasses import dataclass
from typing import IO, Any

from mtcore.text import copy_text, text_style

Source = str | os.PathLike | IO[bytes] | IO[str]
Text = bytes | mmap.mmap  # a file's bytes, read or mapped

LINE_BREAK = re.compile(r"\r\n|\r|\n")  # as the C scanner: CRLF, lone CR and LF each end a line
PARTIAL_PREFIX = ".mt-partial-"  # files being written; a killed run may leave them, the next removes them


def read_source(source: Source) -> tuple[bytes, str | None]:
    """The bytes of a path or file object, and a name for messages."""
    if isinstance(source, (str, os.PathLike)):
        with open_regular(source) as f:
            return f.read(), os.fspath(source)
    data = source.read()
    if isinstance(data, str):
        data = data.encode("utf-8", "surrogateescape")
    return data, getattr(source, "name", None)


@contextlib.contextmanager
def mapped_source(source: Source) -> Iterator[tuple[bytes | mmap.mmap, str | None]]:
    """Like :func:`read_source`, but a file named by path is memory-mapped, not
    copied: large takes are scanned straight from the page cache."""
    if not isinstance(source, (str, os.PathLike)):
        yield read_source(source)
        return
    with open_regular(source) as f:
        if os.fstat(f.fileno()).st_size == 0:
            yield b"", os.fspath(source)
            return
        with mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ) as mapped:
            yield mapped, os.fspath(source)


class InputError(OSError):
    """A path to read that is not a regular file (a device, a FIFO, a socket, a folder) or cannot
    be reached (a symlink loop): the message names the file and says what it is."""

    def __str__(self) -> str:
        return str(self.strerror)


def open_regular(path: str | os.PathLike) -> IO[bytes]:
    """The file at ``path`` opened to read, refused unless it is a regular file: reading a device
    such as /dev/zero never ends, and opening a FIFO waits for a writer (it is opened without
    waiting, then looked at).  FileNotFoundError or :class:`InputError` naming the file."""
    name = os.fspath(path)
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0) | getattr(os, "O_CLOEXEC", 0)
    try:
        fd = os.open(name, flags)
    except OSError as e:
        raise _input_error(name, e) from None
    status = os.fstat(fd)
    if not stat.S_ISREG(status.st_mode):
        os.close(fd)
        raise _not_regular(name, status.st_mode)
    os.set_blocking(fd, True)
    return os.fdopen(fd, "rb")


def regular_file(path: str | os.PathLike) -> os.stat_result:
    """The status of the regular file at ``path``, refused (as :func:`open_regular`) when it is
    anything else; for a caller that reads it later, or elsewhere."""
    name = os.fspath(path)
    try:
        status = os.stat(name)
    except OSError as e:
        raise _input_error(name, e) from None
    if not stat.S_ISREG(status.st_mode):
        raise _not_regular(name, status.st_mode)
    return status


def _not_regular(name: str, mode: int) -> InputError:
    kinds = (
        (stat.S_ISDIR, "a folder"),
        (stat.S_ISFIFO, "a named pipe (FIFO)"),
        (stat.S_ISSOCK, "a socket"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
    )
    kind = next((text for test, text in kinds if test(mode)), "not a file")
    return InputError(errno.EINVAL, f"{name}: {kind}, not a regular file; give a file to read")


def _input_error(name: str, error: OSError) -> OSError:
    """The error of a path that could not be opened or looked at, naming it as the user did."""
    if error.errno == errno.ENOENT:
        broken = os.path.islink(name)
        return FileNotFoundError(f"{name}: {'a symlink to a missing file' if broken else 'no such file'}")
    if error.errno == errno.ELOOP:
        return InputError(error.errno, f"{name}: symlink loop (the links lead back to themselves)")
    if error.errno == errno.ENXIO:  # what opening a socket gives
        with contextlib.suppress(OSError):
            return _not_regular(name, os.stat(name).st_mode)
    return error


@dataclass(frozen=True)
class TextStyle:
    """How a file's text is laid out, so that what is written from it looks the same: its line
    endings (``frame_newline`` for the lines that hold only a frame number, which HDM05 ends in LF
    while every other line ends in CRLF), the fewest digits of an exponent (HDM05: 3, ``e-013``),
    and whether the last line ends in a line break."""

    newline: bytes = b"\n"
    frame_newline: bytes = b"\n"
    exponent_digits: int = 2
    final_newline: bool = True

    @classmethod
    def of(cls, data: bytes | mmap.mmap) -> TextStyle:
        """The style of a file's text."""
        newline, exponent_digits, frame_newline = text_style(data)
        return cls(newline, frame_newline, exponent_digits, copy_text(data, len(data) - 1) in (b"", b"\n", b"\r"))

    def lines(self, lines: list[str]) -> bytes:
        """Header lines as bytes, each ended as the file ends its lines."""
        return encode("".join(line + self.newline.decode() for line in lines))

    def numbers(self) -> dict[str, Any]:
        """The options of mtcore.text's writers for this style (format_frames also takes frame_newline)."""
        return {"exponent_digits": self.exponent_digits, "newline": self.newline}


PLAIN = TextStyle()  # what this package writes when no file says otherwise


@dataclass(frozen=True)
class Origin:
    """The file an object was read from, and the file's size and time then: while they hold, the
    file still says exactly what was read, and writing the unchanged object back can copy it."""

    path: str
    stamp: tuple[int, int]

    @classmethod
    def of(cls, source: Source) -> Origin | None:
        """The origin of a source named by path; None for a file object (it cannot be read again)."""
        if not isinstance(source, (str, os.PathLike)):
            return None
        status = os.stat(source)
        return cls(os.path.abspath(source), (status.st_size, status.st_mtime_ns))

    def intact(self) -> bool:
        """Whether the file is still as it was read."""
        try:
            status = os.stat(self.path)
        except OSError:
            return False
        return (status.st_size, status.st_mtime_ns) == self.stamp

    def copy_to(self, target: Source) -> bool:
        """Write the file's bytes to ``target`` (atomically, as :func:`output`) if it is intact and
        is not the target itself; returns whether it did."""
        if not self.intact():
            return False
        if isinstance(target, (str, os.PathLike)) and os.path.abspath(target) == self.path:
            return True  # writing the file over itself, unchanged: nothing to do
        with open(self.path, "rb") as src, output(target) as dst:
            shutil.copyfileobj(src, dst)
        return True


def decode(data: bytes) -> str:
    """Text of a file whose comments may hold any bytes: undecodable bytes survive
    as surrogates and are written back unchanged by :func:`encode`."""
    return data.decode("utf-8", "surrogateescape")


def encode(text: str) -> bytes:
    """The bytes of :func:`decode`'s text, undecodable bytes restored."""
    return text.encode("utf-8", "surrogateescape")


@contextlib.contextmanager
def output(target: Source) -> Iterator[IO[bytes]]:
    """A binary stream to write to.  For a path, the text goes to a temporary file
    beside it that replaces the path only when complete, so that a failure
    leaves no partial file, and a missing folder is made first; the file gets the permissions any new file gets
    (the umask's).  An OSError names the target, never the temporary file."""
    if not isinstance(target, (str, os.PathLike)):
        yield typing.cast(IO[bytes], target.buffer if isinstance(target, io.TextIOWrapper) else target)
        return
    path = os.fspath(target)
    directory = os.path.dirname(os.path.abspath(path))
    remove_stale_partials(directory)
    made = _missing_folders(directory)
    try:
        os.makedirs(directory, exist_ok=True)  # the folder of a path named for the first time
        fd, tmp = _partial(directory)
    except OSError as e:
        _remove_empty(made)
        raise OutputError(e.errno, f"cannot write {path}: {e.strerror}") from None
    try:
        with os.fdopen(fd, "wb") as f:
            yield f
        os.replace(tmp, path)
    except BaseException as e:
        os.unlink(tmp)
        _remove_empty(made)  # a failed write leaves the disk as it found it
        if isinstance(e, OSError) and e.filename in (None, tmp) and e.errno in WRITE_ERRORS:
            raise OutputError(e.errno, f"cannot write {path}: {e.strerror}") from None
        raise


def _missing_folders(directory: str) -> list[str]:
    """The folders of ``directory`` that do not exist yet, deepest first."""
    missing = []
    while not os.path.isdir(directory) and os.path.dirname(directory) != directory:
        missing.append(directory)
        directory = os.path.dirname(directory)
    return missing


def _remove_empty(folders: list[str]) -> None:
    for folder in folders:
        try:
            os.rmdir(folder)  # only if empty: another writer's file there keeps it
        except OSError:
            return


WRITE_ERRORS = (errno.EACCES, errno.EPERM, errno.EROFS, errno.ENOSPC, errno.EDQUOT, errno.EFBIG)


class OutputError(OSError):
    """A file could not be written (no permission, read-only, disk full): the message names the
    file the user asked for, never the temporary file."""

    def __str__(self) -> str:
        return str(self.strerror)


def _partial(directory: str) -> tuple[int, str]:
    """A new temporary file in ``directory`` (its descriptor and path), named so that a later run
    can tell its writer has died.  Created with mode 0o666 for the system to apply the umask (and a
    folder's default ACL) as to any new file: what it becomes keeps those permissions."""
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0) | getattr(os, "O_CLOEXEC", 0)
    while True:
        tmp = os.path.join(directory, f"{PARTIAL_PREFIX}{os.getpid()}-{secrets.token_hex(6)}.tmp")
        try:
            return os.open(tmp, flags, 0o666), tmp
        except FileExistsError:  # a name another writer took: draw again
            continue


_CLEANED: set[str] = set()


def remove_stale_partials(directory: str | os.PathLike, *, recursive: bool = False) -> int:
    """Remove the temporary files that killed processes left in ``directory`` (and below it,
    ``recursive``); a file being written by a live process is left alone.  A folder is looked
    at once per process unless ``recursive``.  Returns how many were removed."""
    folder = os.fspath(directory)
    if not recursive:
        if folder in _CLEANED:
            return 0
        _CLEANED.add(folder)
    removed = 0
    with contextlib.suppress(OSError), os.scandir(folder) as entries:
        for entry in entries:
            if recursive and entry.is_dir(follow_symlinks=False):
                removed += remove_stale_partials(entry.path, recursive=True)
            elif entry.name.startswith(PARTIAL_PREFIX) and not _alive(entry.name[len(PARTIAL_PREFIX) :]):
                with contextlib.suppress(OSError):
                    os.unlink(entry.path)
                    removed += 1
    return removed


def _alive(rest: str) -> bool:
    """Whether the process whose id starts ``rest`` ("<pid>-...") still runs."""
    pid = rest.split("-", 1)[0]
    if not pid.isdigit():
        return False
    try:
        os.kill(int(pid), 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True
