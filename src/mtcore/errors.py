"""Exceptions for text that does not follow its format.

Every one says where (file and line, when known) and what was expected.
"""

from __future__ import annotations

import copy
import os


class FormatError(ValueError):
    """A file, or text, that breaks the rules of its format."""

    def __init__(self, reason: str, line: int | None = None, path: str | os.PathLike | None = None):
        self.reason, self.line, self.path = reason, line, path
        super().__init__(reason)

    def __str__(self) -> str:
        where = []
        if self.path is not None:
            where.append(os.fspath(self.path))
        if self.line is not None:
            where.append(f"line {self.line}")
        return f"{', '.join(where)}: {self.reason}" if where else self.reason

    def at(self, path: str | os.PathLike | None, line_offset: int = 0) -> FormatError:
        """The same error, placed in file `path` with its line moved down by line_offset."""
        moved = copy.copy(self)
        moved.path = path
        if moved.line is not None:
            moved.line += line_offset
        return moved


class NumberError(FormatError):
    """A token that should be a number is not one."""


class CountError(FormatError):
    """A line with more or fewer values than it must have."""


class UnknownNameError(FormatError):
    """A name (bone, joint, key, channel) that the file or skeleton does not define, whether it
    comes from a file (with its line) or from an argument (without)."""


class DuplicateError(FormatError):
    """A name defined or given twice where once is allowed."""


class MissingError(FormatError):
    """Something required is absent (a section, a key, a bone in a frame)."""


class SequenceError(FormatError):
    """Frames out of order or numbered out of sequence."""


class TruncatedError(MissingError):
    """The file ends before its last record is complete."""


class ChangedFileError(OSError):
    """A memory-mapped file that shrank (another program wrote to it or truncated it) while it was read."""
