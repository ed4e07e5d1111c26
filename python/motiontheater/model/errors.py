"""The exceptions of motiontheater.

Text that breaks its format raises a :class:`FormatError` subclass naming
the file, the line and what was expected (the text scanners of mtcore raise
them too, so they are defined there and re-exported here).  A name that the
skeleton or file does not define raises :class:`UnknownNameError`, wherever
it comes from: a file, a function argument, a command-line flag.
"""

from mtcore.errors import (
    CountError,
    DuplicateError,
    FormatError,
    MissingError,
    NumberError,
    SequenceError,
    TruncatedError,
    UnknownNameError,
)

__all__ = [
    "CountError",
    "DuplicateError",
    "FormatError",
    "HierarchyError",
    "MissingError",
    "NumberError",
    "SequenceError",
    "TruncatedError",
    "UnknownNameError",
]


class HierarchyError(FormatError):
    """A skeleton hierarchy that is not a tree over all bones from the root."""
