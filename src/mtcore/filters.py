"""One-dimensional smoothing filters with the signatures of scipy.ndimage.

Each filter runs along one axis of an n-d array, in C.  float32 and float64
are computed natively (float32 stays float32; means are accumulated in
double); float16 is computed in float32; bool and integer input in float64,
the result cast to the output type as scipy does (truncation toward zero),
but for the median of 64-bit integers beyond 2**53, which float64 would
round: it is exact (computed on the values' ranks).  A NaN or an infinity
affects only the outputs whose windows hold it.
The input is never modified.  ``output`` may be an array of the input's shape
(any dtype, any layout, even the input itself) or a dtype.

Large arrays are split over the cores by frames (``workers``, keyword-only,
as in scipy.fft): None uses every core for arrays of a million values or
more and one thread below; 1 keeps the work in the calling thread; -1 means
every core.  The result does not depend on the number of workers.

Edge modes, for the line ``a b c d`` and fill value ``k = cval``:

====================  ===========================
``reflect``           ``d c b a | a b c d | d c b a``
``nearest``           ``a a a a | a b c d | d d d d``
``mirror``            ``  d c b | a b c d | c b a``
``constant``          ``k k k k | a b c d | k k k k``
``wrap``              ``a b c d | a b c d | a b c d``
====================  ===========================

An extension longer than the line repeats the pattern; scipy's aliases
``grid-mirror``, ``grid-constant`` and ``grid-wrap`` are accepted.  Output
sample ``i`` reads input samples ``i + j - size // 2 - origin`` for
``j = 0 .. size - 1``.

Sizes: any from 1 to :data:`MAX_SIZE` (2**31 - 1) for the median and the
mean; a window longer than the line costs time and memory in proportion to
the line, not to the window.  The binomial filter takes sizes up to
:data:`MAX_BINOMIAL_SIZE` (65537, a Gaussian of standard deviation 128
samples): its weights are exact fractions of integers of ``size`` bits, and
beyond that size they would take seconds to compute while all but the
central ``39 * sqrt(size)`` of them round to 0.  For wider smoothing apply
:func:`uniform_filter1d` three times (a close approximation of a Gaussian).
"""

from __future__ import annotations

import functools
import math

import numpy as np
from numpy.typing import ArrayLike, DTypeLike

from . import _checks
from ._mtcore import ffi, lib
from ._parallel import run_ranges, thread_count

__all__ = [
    "MAX_BINOMIAL_SIZE",
    "MAX_SIZE",
    "MODES",
    "binomial_filter1d",
    "filter_block",
    "median_filter1d",
    "pascal_weights",
    "uniform_filter1d",
]

MODES = {
    "reflect": lib.MT_MODE_REFLECT,
    "grid-mirror": lib.MT_MODE_REFLECT,
    "nearest": lib.MT_MODE_NEAREST,
    "mirror": lib.MT_MODE_MIRROR,
    "constant": lib.MT_MODE_CONSTANT,
    "grid-constant": lib.MT_MODE_CONSTANT,
    "wrap": lib.MT_MODE_WRAP,
    "grid-wrap": lib.MT_MODE_WRAP,
}

MAX_SIZE = 2**31 - 1  # samples: a window no capture comes near (20 days at 1200 Hz)
MAX_BINOMIAL_SIZE = 2**16 + 1  # see the module's docstring

# Below this, handing work to another thread costs more than it saves.
_PARALLEL_MIN_VALUES = 1 << 20

_NATIVE = {np.dtype(np.float64): lib.MT_FLOAT64, np.dtype(np.float32): lib.MT_FLOAT32}
_F32, _F64 = np.dtype(np.float32), np.dtype(np.float64)


@functools.lru_cache(maxsize=64)
def _pascal(size: int) -> np.ndarray:
    n = size - 1
    top = 1 << n
    w = np.zeros(size)
    # From the middle outwards, C(n, k - 1) = C(n, k) k / (n - k + 1) exactly, by symmetry
    # both halves at once, until the weights round to 0: a few thousand steps on integers of
    # n bits.  Python integers are exact, and int / int rounds correctly even for huge rows.
    c = math.comb(n, n // 2)
    for k in range(n // 2, -1, -1):
        weight = c / top
        if weight == 0.0:
            break
        w[k] = w[n - k] = weight
        c = c * k // (n - k + 1)
    w.flags.writeable = False
    return w


def pascal_weights(size: int) -> np.ndarray:
    """Row ``size - 1`` of Pascal's triangle divided by its sum ``2**(size - 1)``.

    size 3: ``[1, 2, 1] / 4``; size 5: ``[1, 4, 6, 4, 1] / 16``.  Every weight
    is the correctly rounded float64 of the exact fraction (0.0 where that is
    below the smallest subnormal, the outer weights of sizes above 1075).
    Returns a new float64 array of length ``size``, 1 to
    :data:`MAX_BINOMIAL_SIZE`.
    """
    return _pascal(_check_size(size, binomial=True)).copy()


def filter_block(size: int) -> int:
    """The frames of the blocks the filters of window ``size`` work in: a call on frames that begin
    at a multiple of it gives, bit for bit, what one call over all frames gives there (the running
    sums of the mean restart at those multiples), so that a take can be filtered in pieces."""
    return int(lib.mt_filter1d_block(_check_size(size)))


def median_filter1d(
    input: ArrayLike,
    size: int,
    axis: int = -1,
    output: np.ndarray | DTypeLike | None = None,
    mode: str = "reflect",
    cval: float = 0.0,
    origin: int = 0,
    *,
    workers: int | None = None,
) -> np.ndarray:
    """Moving median of ``size`` samples along ``axis``.

    Gives the same result as ``scipy.ndimage.median_filter(input, size=size,
    axes=(axis,), mode=mode, cval=cval, origin=origin)``: for an even size the
    upper of the two middle values (rank ``size // 2``), never an average, so
    the median never invents values, 64-bit integers included.  A window
    that contains NaN gives NaN (scipy's result is undefined there).
    """
    return _filter1d(lib.MT_FILTER_MEDIAN, input, size, axis, output, mode, cval, origin, workers)


def uniform_filter1d(
    input: ArrayLike,
    size: int,
    axis: int = -1,
    output: np.ndarray | DTypeLike | None = None,
    mode: str = "reflect",
    cval: float = 0.0,
    origin: int = 0,
    *,
    workers: int | None = None,
) -> np.ndarray:
    """Moving average of ``size`` samples along ``axis``.

    The same result as ``scipy.ndimage.uniform_filter1d`` (to rounding: a
    running sum in double, restarted every few hundred samples so that long
    lines do not drift).
    """
    return _filter1d(lib.MT_FILTER_UNIFORM, input, size, axis, output, mode, cval, origin, workers)


def binomial_filter1d(
    input: ArrayLike,
    size: int,
    axis: int = -1,
    output: np.ndarray | DTypeLike | None = None,
    mode: str = "reflect",
    cval: float = 0.0,
    origin: int = 0,
    *,
    workers: int | None = None,
) -> np.ndarray:
    """Pascal-triangle weighted average of ``size`` samples along ``axis``.

    The weights are :func:`pascal_weights` (size 3: 1 2 1 / 4; size 7:
    1 6 15 20 15 6 1 / 64), the smoothing filter of the MotionTheater thesis.
    The same result as ``scipy.ndimage.correlate1d(input,
    pascal_weights(size), axis, ...)``, to rounding.
    """
    return _filter1d(lib.MT_FILTER_CORRELATE, input, size, axis, output, mode, cval, origin, workers)


def _check_size(size, *, binomial: bool = False) -> int:
    if binomial:
        note = " samples for the binomial filter (wider smoothing: uniform_filter1d three times; see mtcore.filters)"
        return _checks.integer(size, "size", 1, MAX_BINOMIAL_SIZE, note=note)
    return _checks.integer(size, "size", 1, MAX_SIZE, note=" samples")


def _work_dtype(dtype: np.dtype, role: str = "input") -> np.dtype:
    """The native float type the C kernel computes ``dtype`` in."""
    _checks.real_dtype(dtype, role, "the filters compute in at most float64")
    native = dtype.newbyteorder("=")
    if native in _NATIVE:
        return native
    return _F32 if native == np.float16 else _F64


def _split(workers: int | None, values: int, frames: int, block: int) -> list[int]:
    """Frame bounds of the ranges the threads compute: multiples of the C block
    length, so that the result is the same bit for bit however it is split."""
    wanted = thread_count(workers, values >= _PARALLEL_MIN_VALUES)
    blocks = -(-frames // block)
    threads = max(1, min(wanted, blocks))
    return [min(frames, blocks * i // threads * block) for i in range(threads)] + [frames]


def _filter1d(kind, input, size, axis, output, mode, cval, origin, workers):
    a = np.asarray(input)
    work = _work_dtype(a.dtype)
    binomial = kind == lib.MT_FILTER_CORRELATE
    size = _check_size(size, binomial=binomial)
    axis = _checks.axis(axis, a.ndim)
    code = _checks.choice(mode, "mode", MODES)
    try:
        cval = float(cval)
    except (TypeError, ValueError):
        raise TypeError(f"cval must be a real number, got {cval!r}") from None
    origin = _checks.integer(origin, "origin", -(size // 2), (size - 1) // 2, note=f" for size {size}")
    target = _target(output, a)
    if kind == lib.MT_FILTER_MEDIAN and not _exact_in_float64(a):
        return _median_by_rank(a, size, axis, target, mode, cval, origin, workers)

    outer, n, inner = math.prod(a.shape[:axis]), a.shape[axis], math.prod(a.shape[axis + 1 :])
    bounds = _split(workers, a.size, n, lib.mt_filter1d_block(size))
    if a.dtype != work or not (a.flags.c_contiguous and a.flags.aligned):
        a = np.require(a, work, ["C", "A"])
    # The kernel writes straight into the target when it has the kernel's layout
    # and type and does not overlap the input; otherwise into a temporary.
    direct = (
        target.dtype == work
        and target.flags.c_contiguous
        and target.flags.aligned
        and not np.may_share_memory(target, a)
    )
    result = target if direct else np.empty(a.shape, work)
    if a.size:
        weights = ffi.from_buffer("double[]", _pascal(size)) if binomial else ffi.NULL
        head = (kind, _NATIVE[work], ffi.from_buffer(a), ffi.from_buffer(result), outer, n, inner)
        tail = (size, origin, code, cval, weights)
        run_ranges(lambda begin, end: lib.mt_filter1d(*head, begin, end, *tail), bounds, "mt_filter1d")
    if not direct:
        _store(target, result)
    return target


def _store(target: np.ndarray, result, where=True) -> None:
    """Cast ``result`` into ``target`` as scipy does."""
    if target.dtype == np.bool_:
        # scipy stores through npy_bool, an unsigned char: values truncate, so only |x| >= 1 is True.
        result = np.abs(result) >= 1
    np.copyto(target, result, casting="unsafe", where=where)


def _exact_in_float64(a: np.ndarray) -> bool:
    """Whether float64 holds every value of ``a`` exactly (64-bit integers beyond 2**53 it does not)."""
    if a.dtype.kind not in "iu" or a.dtype.itemsize < 8 or not a.size:
        return True
    return -(2**53) <= int(a.min()) and int(a.max()) <= 2**53


def _median_by_rank(a: np.ndarray, size, axis, target, mode, cval, origin, workers) -> np.ndarray:
    """The median of 64-bit integers beyond float64's exact range, exactly.

    A median is a rank: it commutes with any increasing map.  The values are
    replaced by their ranks among the distinct values (float64 holds those
    exactly), the ranks filtered, and the ranks of the result looked up.
    cval, a float, gets the rank of its place among the values (a half rank
    between two of them), so that it orders exactly as it does against them.
    """
    values = np.unique(a)
    ranks = np.searchsorted(values, a).astype(np.float64)
    if math.isnan(cval):
        cval_rank = math.nan
    else:
        # the values below cval are those below ceil(cval), compared as Python integers (exact)
        ceiling = math.ceil(cval) if math.isfinite(cval) else int(math.copysign(2**64, cval))
        if ceiling <= int(values[0]):
            below = 0
        elif ceiling > int(values[-1]):
            below = len(values)
        else:
            below = int(np.searchsorted(values, ceiling))
        equal = below < len(values) and cval == int(values[below])
        cval_rank = float(below) if equal else below - 0.5
    picked = _filter1d(lib.MT_FILTER_MEDIAN, ranks, size, axis, None, mode, cval_rank, origin, workers)
    exact = picked == np.floor(picked)
    _store(target, values[np.where(exact, picked, 0).astype(np.intp)], where=exact)
    if not exact.all():
        _store(target, np.float64(cval), where=~exact)
    return target


def _target(output, a: np.ndarray) -> np.ndarray:
    """The array the result goes to: ``output``, or a new one of its dtype or the input's."""
    if output is None:
        return np.empty(a.shape, a.dtype.newbyteorder("="))
    if isinstance(output, np.ndarray):
        _checks.output(output, "output", a.shape, None, contiguous=False)
        _work_dtype(output.dtype, "output")
        return output
    try:
        dtype = np.dtype(output)
    except TypeError:
        raise TypeError(f"output must be None, an ndarray or a dtype, got {output!r}") from None
    _work_dtype(dtype, "output")
    return np.empty(a.shape, dtype)
