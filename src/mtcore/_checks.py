"""Argument checks shared by the array functions (as scipy.ndimage's ``_ni_support``): integers
and their ranges, axes, choices from a set, flags, real arrays and output arrays, with one
wording: a message names the argument, what it must be, and what it got."""

from __future__ import annotations

import operator
import reprlib
from collections.abc import Collection, Mapping

import numpy as np

_DIMENSIONS = {0: "a number", 1: "one-dimensional", 2: "two-dimensional", 3: "three-dimensional"}


def _got(value) -> str:
    """A value as a message shows what it got: its type and a short repr."""
    return "None" if value is None else f"{type(value).__name__} {reprlib.repr(value)}"


def integer(value, name: str, low: int | None = None, high: int | None = None, *, note: str = "") -> int:
    """``value`` as an int within low .. high (inclusive; None: unbounded).  ``note`` follows the
    range in the message (a unit, a reason).  TypeError for a non-integer, bool included (a
    flag is no count); ValueError out of range."""
    if isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name} must be an integer, got {_got(value)}")
    try:
        number = operator.index(value)
    except TypeError:
        raise TypeError(f"{name} must be an integer, got {_got(value)}") from None
    if (low is None or number >= low) and (high is None or number <= high):
        return number
    rule = (
        f"in [{low}, {high}]"
        if low is not None and high is not None
        else f"at least {low}"
        if high is None
        else f"at most {high}"
    )
    raise ValueError(f"{name} must be {rule}{note}, got {number}")


def axis(value, ndim: int, name: str = "axis") -> int:
    """``value`` as an axis of an array of ``ndim`` dimensions, negatives counted from the end.
    numpy's AxisError (a ValueError and an IndexError) out of range."""
    number = integer(value, name)
    if -ndim <= number < ndim:
        return number % ndim
    rule = f"in [{-ndim}, {ndim - 1}]" if ndim else "an axis of the array (a 0-dimensional array has none)"
    raise np.exceptions.AxisError(f"{name} must be {rule} for a {ndim}-dimensional array, got {number}")


def choice(value, name: str, choices: Collection | Mapping, *, hint: str = ""):
    """``choices[value]`` for a mapping (the code a name stands for), else ``value``, when it is one
    of ``choices``; ValueError naming them all otherwise.  ``hint`` ends the message."""
    try:
        known = value in choices
    except TypeError:  # unhashable
        known = False
    if not known:
        raise ValueError(f"{name} must be one of {', '.join(map(repr, choices))}; got {value!r}{hint}")
    return choices[value] if isinstance(choices, Mapping) else value


def flag(value, name: str) -> bool:
    """``value`` as a bool: True or False only (a 1 or a "yes" is more likely a misplaced argument)."""
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name} must be True or False, got {value!r}")
    return bool(value)


def real_dtype(dtype: np.dtype, name: str, widest: str = "") -> np.dtype:
    """``dtype`` if it holds real numbers (bool, integer or float), else TypeError.  With ``widest``
    (why) floats wider than float64 are refused too rather than rounded."""
    if dtype.kind not in "biuf":
        raise TypeError(f"{name} must hold real numbers (bool, integer or float), got dtype {dtype}")
    if widest and dtype.kind == "f" and dtype.itemsize > 8:
        raise TypeError(
            f"{name} must hold at most float64 ({widest}), got dtype {dtype}; "
            "convert with .astype(numpy.float64) if the loss of precision is acceptable"
        )
    return dtype


def output(a, name: str, shape: tuple, dtype=np.float64, *, contiguous: bool = True) -> np.ndarray:
    """Check an output array given: a writeable ndarray of ``shape`` (as for :func:`real`) and, unless
    None, ``dtype``; C-contiguous unless told otherwise.  ValueError naming what is wrong."""
    problem = (
        _got(a) if not isinstance(a, np.ndarray)
        else f"dtype {a.dtype}" if dtype is not None and a.dtype != dtype
        else f"shape {a.shape}" if not _fits(a, shape)
        else "a read-only array" if not a.flags.writeable
        else "an array that is not C-contiguous" if contiguous and not a.flags.c_contiguous
        else ""
    )  # fmt: skip
    if problem:  # the message made only when it is needed: outputs are checked on every call
        kind = "" if dtype is None else f" {np.dtype(dtype)}"
        wanted = f"a writeable{' C-contiguous' if contiguous else ''}{kind} array of shape {_shown(shape)}"
        raise ValueError(f"{name} must be {wanted}, got {problem}")
    return a


def real(a, name: str, shape: tuple, keep: tuple = ()) -> np.ndarray:
    """``a`` as a C-contiguous float64 array of ``shape`` (None: any length there; a leading
    ``...``: any leading axes; a string: any length, named so in messages), or of its own dtype
    where that is one of ``keep``.

    TypeError for None or a dtype that is not bool, integer or float; ValueError for another shape.
    """
    if type(a) is np.ndarray and a.dtype == np.float64 and a.flags.c_contiguous and _fits(a, shape):
        return a  # what the kernels' callers nearly always pass: nothing to convert
    array = _array(a, name)
    real_dtype(array.dtype, name)
    _shape(array, name, shape)
    dtype = array.dtype if array.dtype in keep else np.float64
    return np.asarray(array, dtype=dtype, order="C")  # ascontiguousarray would make 0-d 1-d


def integers(a, name: str, shape: tuple, low: int, high: int, dtype=np.int64) -> np.ndarray:
    """``a`` as a C-contiguous array of ``dtype`` and ``shape`` whose entries lie in low .. high - 1.

    TypeError for None or a dtype that is not bool or integer (an empty list passes); ValueError
    for another shape or the first entry out of range, named by its index.
    """
    array = _array(a, name)
    if array.dtype.kind not in "biu" and array.size:
        raise TypeError(f"{name} must hold integers, got dtype {array.dtype}")
    _shape(array, name, shape)
    if array.size and not _within(array, low, high):
        outside = (array < low) | (array >= high)
        at = tuple(int(i) for i in np.argwhere(outside)[0])
        where = at[0] if len(at) == 1 else at
        raise ValueError(f"{name} must lie in {low} .. {high - 1}, got {name}[{where}] = {int(array[at])}")
    return np.asarray(array, dtype=dtype, order="C")


def _within(array: np.ndarray, low: int, high: int) -> bool:
    """Whether every entry of a non-empty integer array lies in low .. high - 1: as Python numbers
    for the few entries most calls pass (a microsecond less than numpy's masks)."""
    if array.size <= 64:
        values = array.ravel().tolist()
        return min(values) >= low and max(values) < high
    return bool(array.min() >= low and array.max() < high)


def flags(a, name: str, count: int, dtype=np.intc) -> np.ndarray:
    """``a``, one flag or ``count`` of them, as ``count`` 0s and 1s of ``dtype`` (C-contiguous);
    ValueError for another shape.  (np.broadcast_to costs several microseconds a call.)"""
    array = np.asarray(a, dtype=bool)
    if array.shape in ((), (1,)):
        return np.full(count, bool(array.reshape(())), dtype)
    if array.shape != (count,):
        raise ValueError(f"{name} must be one flag or {count} of them, got shape {array.shape}")
    return array.astype(dtype)


def fractions(a, name: str, length: int) -> np.ndarray:
    """``a`` as float64 of shape (length,) with every entry in [0, 1] (NaN refused)."""
    array = real(a, name, (length,))
    outside = ~((array >= 0) & (array <= 1))
    if outside.any():
        i = int(np.flatnonzero(outside)[0])
        raise ValueError(f"{name} must lie in [0, 1], got {name}[{i}] = {float(array[i])!r}")
    return array


def _array(a, name: str) -> np.ndarray:
    if a is None:
        raise TypeError(f"{name} must be an array, got None")
    try:
        return np.asarray(a)
    except ValueError as e:  # ragged nested sequences
        raise ValueError(f"{name} must be a rectangular array: {e}") from None


def _fits(array: np.ndarray, shape: tuple) -> bool:
    """Whether array has ``shape``: None or a name is any length, a leading ... any leading axes."""
    if shape[:1] == (...,):
        shape = shape[1:]
        if array.ndim < len(shape):
            return False
        got = array.shape[array.ndim - len(shape) :]
    elif array.ndim != len(shape):
        return False
    else:
        got = array.shape
    # a plain loop: this runs on every call of the small wrappers, where a generator costs a microsecond
    for want, n in zip(shape, got):
        if want != n and want is not None and not isinstance(want, str):
            return False
    return True


def _shown(shape: tuple) -> str:
    words = ["..." if n is ... else "any" if n is None else str(n) for n in shape]
    return "(" + ", ".join(words) + ("," if len(shape) == 1 else "") + ")"


def _shape(array: np.ndarray, name: str, shape: tuple) -> None:
    """Raise unless array has ``shape`` (see _fits)."""
    if _fits(array, shape):
        return
    if shape[:1] == (...,):
        raise ValueError(f"{name} must have shape {_shown(shape)}, got shape {array.shape}")
    kind = _DIMENSIONS.get(len(shape), f"{len(shape)}-dimensional")
    raise ValueError(f"{name} must be {kind} of shape {_shown(shape)}, got shape {array.shape}")
