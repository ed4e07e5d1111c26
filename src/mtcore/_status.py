"""The one place where C status codes become Python exceptions."""

from ._mtcore import ffi, lib

_EXCEPTIONS = {
    lib.MT_EINVAL: ValueError,
    lib.MT_ENOMEM: MemoryError,
    lib.MT_EDTYPE: TypeError,
}


def check(status: int, what: str) -> None:
    """Raise the exception for a non-zero status of the C call named by ``what``.

    Python validates arguments before every call, so an error here means a
    broken invariant or exhausted memory; the message says which call failed
    and what the C core reported.
    """
    if status == lib.MT_OK:
        return
    message = ffi.string(lib.mt_strerror(status)).decode()
    exc = _EXCEPTIONS.get(status, RuntimeError)
    raise exc(f"{what}: {message} (status {status})")
