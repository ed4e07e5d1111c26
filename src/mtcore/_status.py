"""The one place where C status codes become Python exceptions."""

from __future__ import annotations

import typing
from collections.abc import Callable

from . import errors
from ._mtcore import ffi, lib

_EXCEPTIONS: dict[int, type[Exception]] = {
    lib.MT_EINVAL: ValueError,
    lib.MT_ENOMEM: MemoryError,
    lib.MT_EDTYPE: TypeError,
    lib.MT_ESYNTAX: errors.NumberError,
    lib.MT_ECOUNT: errors.CountError,
    lib.MT_EUNKNOWN: errors.UnknownNameError,
    lib.MT_EDUPLICATE: errors.DuplicateError,
    lib.MT_EMISSING: errors.MissingError,
    lib.MT_EFRAME: errors.SequenceError,
    lib.MT_EFRAMERANGE: errors.SequenceError,
    # a table with more rows than its header declares (mt_scan_table); elsewhere an output
    # buffer below its bound, which Python sizes, so a broken invariant
    lib.MT_ERANGE: errors.SequenceError,
    lib.MT_EIO: errors.ChangedFileError,
}


def check(status: int, what: str, describe: Callable[[int], tuple[str, int, bool]] | None = None) -> None:
    """Raise the exception for a non-zero status of the C call named by ``what``.

    Argument errors (Python validates before every call, so these mean a
    broken invariant) and exhausted memory name the call and the C message.
    Errors in scanned text are FormatErrors whose reason and line come from
    ``describe(status)`` -> (reason, line, truncated), the caller knowing the text.
    """
    if status == lib.MT_OK:
        return
    exc = _EXCEPTIONS.get(status, RuntimeError)
    if describe is not None and issubclass(exc, errors.FormatError):
        reason, line, truncated = describe(status)
        raise (errors.TruncatedError if truncated else exc)(reason, line)
    message = typing.cast(bytes, ffi.string(lib.mt_strerror(status))).decode()
    raise exc(f"{what}: {message} (status {status})")
