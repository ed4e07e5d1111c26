"""Argument checks shared by the array functions: dtypes, shapes, index ranges, with messages
that name the argument, what it must be, and what it was."""

from __future__ import annotations

import numpy as np

_DIMENSIONS = {0: "a number", 1: "one-dimensional", 2: "two-dimensional", 3: "three-dimensional"}


def real(a, name: str, shape: tuple) -> np.ndarray:
    """``a`` as a C-contiguous float64 array of ``shape`` (None: any length there; a leading
    ``...``: any leading axes).

    TypeError for None or a dtype that is not bool, integer or float; ValueError for another shape.
    """
    array = _array(a, name)
    if array.dtype.kind not in "biuf":
        raise TypeError(f"{name} must hold real numbers, got dtype {array.dtype}")
    _shape(array, name, shape)
    return np.asarray(array, dtype=np.float64, order="C")  # ascontiguousarray would make 0-d 1-d


def integers(a, name: str, shape: tuple, low: int, high: int, dtype=np.int64) -> np.ndarray:
    """``a`` as a C-contiguous array of ``dtype`` and ``shape`` whose entries lie in low .. high - 1.

    TypeError for None or a dtype that is not bool or integer (an empty list passes); ValueError
    for another shape or the first entry out of range, named by its index.
    """
    array = _array(a, name)
    if array.dtype.kind not in "biu" and array.size:
        raise TypeError(f"{name} must hold integers, got dtype {array.dtype}")
    _shape(array, name, shape)
    outside = (array < low) | (array >= high) if array.size else np.zeros(array.shape, bool)
    if outside.any():
        at = tuple(int(i) for i in np.argwhere(outside)[0])
        where = at[0] if len(at) == 1 else at
        raise ValueError(f"{name} must lie in {low} .. {high - 1}, got {name}[{where}] = {int(array[at])}")
    return np.asarray(array, dtype=dtype, order="C")


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


def _shape(array: np.ndarray, name: str, shape: tuple) -> None:
    """Raise unless array has ``shape``: None is any length, a leading ... any leading axes."""
    if shape[:1] == (...,):
        trailing = shape[1:]
        got = array.shape[array.ndim - len(trailing) :] if array.ndim >= len(trailing) else None
        if got is None or any(want is not None and want != n for want, n in zip(trailing, got)):
            wanted = ", ".join(["..."] + ["any" if n is None else str(n) for n in trailing])
            raise ValueError(f"{name} must have shape ({wanted}), got shape {array.shape}")
        return
    if array.ndim == len(shape) and all(want is None or want == got for want, got in zip(shape, array.shape)):
        return
    wanted = "(" + ", ".join("any" if n is None else str(n) for n in shape) + ("," if len(shape) == 1 else "") + ")"
    kind = _DIMENSIONS.get(len(shape), f"{len(shape)}-dimensional")
    raise ValueError(f"{name} must be {kind} of shape {wanted}, got shape {array.shape}")
