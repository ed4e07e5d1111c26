"""Signal processing along one axis of an array, in C: a band equaliser, zero-phase
Butterworth filtering, polyphase resampling and gap filling.

Drop-in replacements where scipy.signal has the function, with its signature and
results (to rounding) for what they cover:

- :func:`butter_sos` is ``scipy.signal.butter(N, Wn, btype, output="sos", fs=fs)``;
- :func:`sosfilt_zi` and :func:`sosfiltfilt` are scipy's, any section count;
- :func:`resample_poly` is scipy's, with the same FIR design (a Kaiser window,
  beta 5, by default) and the same edge handling (``padtype``).

and functions scipy has not:

- :func:`equalize`: the motion signal processing of Bruderlin and Williams
  (SIGGRAPH 1995): the line split into frequency bands, each band scaled;
- :func:`fill_gaps` and :func:`nan_runs`: runs of NaN filled (linearly or by a
  cubic spline) where short, listed where not;
- :func:`residual_cutoff`: Winter's residual analysis, a Butterworth cut-off
  chosen from the data.

Every function computes in float64 and returns float64 (scipy.signal does too
for these, except that its resample_poly keeps float32).  Inputs may have any
real dtype, shape and memory layout and are never modified.  Large arrays are
split over the cores (``workers``, keyword-only, as in :mod:`mtcore.filters`):
None uses every core for a million values or more, 1 stays in the calling
thread, -1 uses every core; the result does not depend on it.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from fractions import Fraction
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from . import _checks
from ._cdata import c_array
from ._mtcore import ffi, lib
from ._parallel import even_bounds, run_ranges, thread_count
from ._status import check

__all__ = [
    "GapFill",
    "ResidualAnalysis",
    "band_count",
    "butter_sos",
    "equalize",
    "fill_gaps",
    "nan_runs",
    "rational_ratio",
    "resample_poly",
    "residual_cutoff",
    "sosfilt_zi",
    "sosfiltfilt",
]

# Below this, handing work to another thread costs more than it saves.
_PARALLEL_MIN_VALUES = 1 << 20
# Threads split channels at multiples of this (a cache line of float64), so that they never share a line.
_CHANNEL_GRAIN = 8
# sosfiltfilt's threads by default take slabs of at least this many channels (see there).
_SLAB_MIN_CHANNELS = 64

_EQUALIZE_MODES = {
    "reflect": lib.MT_MODE_REFLECT,
    "nearest": lib.MT_MODE_NEAREST,
    "mirror": lib.MT_MODE_MIRROR,
    "constant": lib.MT_MODE_CONSTANT,
    "wrap": lib.MT_MODE_WRAP,
}
_PADTYPES = {"odd": lib.MT_PAD_ODD, "even": lib.MT_PAD_EVEN, "constant": lib.MT_PAD_CONSTANT, None: lib.MT_PAD_NONE}
_BTYPES = {
    "low": "low",
    "lowpass": "low",
    "lp": "low",
    "high": "high",
    "highpass": "high",
    "hp": "high",
    "band": "band",
    "bandpass": "band",
    "bp": "band",
}
_FILL_METHODS = {"linear": lib.MT_FILL_LINEAR, "cubic": lib.MT_FILL_CUBIC}
_WINDOWS: dict[str, Callable[[int], np.ndarray]] = {
    "hamming": np.hamming,
    "hann": np.hanning,
    "blackman": np.blackman,
    "bartlett": np.bartlett,
    "boxcar": np.ones,
}
# resample_poly's padtypes: background values subtracted first, and edge extensions.
_BACKGROUNDS: dict[str, Callable[..., np.ndarray]] = {
    "mean": np.mean,
    "median": np.median,
    "minimum": np.min,
    "maximum": np.max,
}
_EXTENSIONS = ("constant", "line", "edge", "smooth", "symmetric", "reflect", "wrap", "antisymmetric", "antireflect")


# ---------------------------------------------------------------------------
# lines: the filtered axis first, the others flattened into channels


def _float_array(x: ArrayLike, name: str = "x") -> np.ndarray:
    a = np.asarray(x)
    _checks.real_dtype(a.dtype, name, "the signal functions compute in float64")
    return a


def _axis(a: np.ndarray, axis) -> int:
    if a.ndim == 0:
        raise ValueError("x must have at least one dimension, got a 0-dimensional array")
    return _checks.axis(axis, a.ndim)


def _lines(a: np.ndarray, axis: int) -> np.ndarray:
    """``a`` as a C-contiguous float64 (n, channels) array, its axis ``axis`` first (a view where it can be)."""
    moved = np.moveaxis(a, axis, 0)
    return np.ascontiguousarray(moved, dtype=np.float64).reshape(moved.shape[0], math.prod(moved.shape[1:]))


def _unlines(lines: np.ndarray, a: np.ndarray, axis: int) -> np.ndarray:
    """The (n', channels) result back in the layout of ``a``, its axis ``axis`` n' long."""
    moved = np.moveaxis(a, axis, 0).shape[1:]
    return np.moveaxis(lines.reshape((lines.shape[0], *moved)), 0, axis)


def _channel_bounds(workers: int | None, lines: np.ndarray, min_width: int = 1) -> list[int]:
    """Channel bounds of the slabs the threads take, at multiples of a cache line (see thread_count); for
    workers=None no slab narrower than ``min_width`` channels."""
    channels = lines.shape[1]
    wanted = thread_count(workers, lines.size >= _PARALLEL_MIN_VALUES)
    if workers is None:
        wanted = min(wanted, max(1, channels // min_width))
    grains = -(-channels // _CHANNEL_GRAIN)
    return [min(channels, b * _CHANNEL_GRAIN) for b in even_bounds(grains, wanted)] if channels else [0, 0]


def _run_slabs(
    name: str,
    lines: np.ndarray,
    out: np.ndarray,
    workers: int | None,
    call: Callable[..., int],
    min_width: int = 1,
) -> None:
    """``call(in_pointer, out_pointer, channels)`` for each thread's slab of channels (see _channel_bounds)."""
    src, dst = c_array(lines), c_array(out)
    bounds = _channel_bounds(workers, lines, min_width)
    run_ranges(lambda c0, c1: call(src + c0, dst + c0, c1 - c0), bounds, name)


# ---------------------------------------------------------------------------
# the band equaliser


def band_count(frames: int) -> int:
    """Bands of a line of ``frames`` samples: floor(log2(frames)) (0 for fewer than 2 frames)."""
    frames = _checks.integer(frames, "frames", 0)
    return frames.bit_length() - 1 if frames else 0


def equalize(
    x: ArrayLike,
    gains: Sequence[float],
    axis: int = 0,
    mode: str = "nearest",
    cval: float = 0.0,
    *,
    workers: int | None = None,
) -> np.ndarray:
    """The line split into frequency bands, each band scaled by its gain (Bruderlin and Williams 1995).

    Levels of a pyramid without decimation: G_0 = x, G_{k+1} = G_k correlated
    with the binomial kernel (1 4 6 4 1) / 16 whose taps are 2^k samples apart
    (every level keeps all samples); band k = G_k - G_{k+1}, band 0 the highest
    frequencies (periods of about 2 to 4 samples), each next band an octave
    lower.  A line of n samples has ``band_count(n)`` = floor(log2 n) bands;
    the result is ``G_fb + sum_k gains[k] * band_k``.  ``gains`` gives bands
    0, 1, ... in turn; bands after the last gain given keep gain 1.  The sum is
    computed as ``x + sum_k (gains[k] - 1) * band_k`` (the same, as the bands
    telescope), so that gains of 1 return x exactly.

    ``mode`` extends each level past the line's ends as in
    :mod:`mtcore.filters` (``cval`` for "constant").  The default "nearest"
    holds the end values, as a capture that starts and ends at rest does; it
    never reads frames far from an end, whereas "reflect" and "mirror" fold
    the line back on itself (the coarse levels' taps reach up to n samples
    out), so that a trend such as a walk would pull the ends of its low bands
    back towards earlier frames.  Shape and axis as x; float64.
    """
    a = _float_array(x)
    axis = _axis(a, axis)
    code = _checks.choice(mode, "mode", _EQUALIZE_MODES)
    try:
        g = np.array(gains, dtype=np.float64)
    except (TypeError, ValueError):
        g = None
    if g is None or g.ndim != 1:
        raise TypeError(f"gains must be a sequence of numbers, got {gains!r}")
    if not np.all(np.isfinite(g)):
        raise ValueError(f"gains must be finite numbers, got {list(gains)}")
    n = a.shape[axis]
    if len(g) > band_count(n):
        raise ValueError(
            f"{len(g)} gains given, but a line of {n} samples has only {band_count(n)} bands (floor(log2 {n}))"
        )
    lines = _lines(a, axis)
    out = np.empty_like(lines)
    if lines.size:
        gp = c_array(g) if len(g) else ffi.NULL
        stride, cval = lines.shape[1], float(cval)
        _run_slabs(
            "mt_equalize",
            lines,
            out,
            workers,
            lambda src, dst, channels: lib.mt_equalize(src, dst, n, channels, stride, len(g), gp, code, cval),
        )
    return _unlines(out, a, axis)


# ---------------------------------------------------------------------------
# Butterworth design (tiny: numpy) and forward-backward filtering (C)


def butter_sos(N: int, Wn: float | Sequence[float], btype: str = "low", *, fs: float | None = None) -> np.ndarray:
    """Second-order sections (sections, 6) of a digital Butterworth filter of order N.

    As ``scipy.signal.butter(N, Wn, btype, output="sos", fs=fs)``: the analog
    prototype's poles moved to the (prewarped) cut-off, low-, high- or
    band-pass, mapped by the bilinear transform and paired into sections as
    scipy's ``zpk2sos`` pairs them (the poles nearest the unit circle last,
    each with its nearest zeros).  ``Wn`` is the cut-off (two for "band": low,
    high) as a fraction of the Nyquist frequency, or in the units of ``fs``
    (Hz) when the sampling rate ``fs`` is given.  ``btype`` is "low", "high"
    or "band" (or scipy's "lowpass", "highpass", "bandpass").  A band-pass of
    order N has 2N poles.
    """
    order = _checks.integer(N, "N", 1)
    kind = _checks.choice(btype, "btype", _BTYPES)
    w = np.atleast_1d(np.asarray(Wn, dtype=np.float64))
    if w.ndim != 1 or len(w) != (2 if kind == "band" else 1):
        need = "two frequencies (low, high)" if kind == "band" else "one frequency"
        raise ValueError(f"a {kind}-pass filter needs {need} in Wn, got {Wn!r}")
    if fs is not None:
        fs = float(fs)
        if not (math.isfinite(fs) and fs > 0):
            raise ValueError(f"fs must be a positive sampling rate, got {fs}")
        w = w / (fs / 2)
    if not np.all((w > 0) & (w < 1)):
        limit = f"0 < Wn < fs/2 = {fs / 2:g}" if fs is not None else "0 < Wn < 1 (1 is the Nyquist frequency)"
        raise ValueError(f"cut-off frequencies must be {limit}, got {Wn!r}")
    if kind == "band" and not w[0] < w[1]:
        raise ValueError(f"the band's low cut-off must be below its high one, got {Wn!r}")

    # the analog prototype: N poles on the left unit half circle, no zeros, gain 1
    poles = -np.exp(1j * np.pi * np.arange(-order + 1, order, 2, dtype=np.float64) / (2 * order))
    warped = 4.0 * np.tan(np.pi * w / 2.0)  # prewarped for the bilinear transform at fs = 2
    zeros = np.zeros(0, dtype=complex)
    if kind == "low":
        poles, gain = warped[0] * poles, warped[0] ** order
    elif kind == "high":
        gain = np.real(1.0 / np.prod(-poles))
        poles, zeros = warped[0] / poles, np.zeros(order, dtype=complex)
    else:
        bw, wo = warped[1] - warped[0], np.sqrt(warped[0] * warped[1])
        half = (poles * bw / 2).astype(np.complex128)
        root = np.sqrt(half**2 - wo**2)
        poles, zeros, gain = np.concatenate((half + root, half - root)), np.zeros(order, dtype=complex), bw**order
    # bilinear transform at fs = 2; zeros at infinity go to z = -1
    degree = len(poles) - len(zeros)
    zd = np.concatenate(((4.0 + zeros) / (4.0 - zeros), -np.ones(degree)))
    pd = (4.0 + poles) / (4.0 - poles)
    gain = gain * np.real(np.prod(4.0 - zeros) / np.prod(4.0 - poles))
    return _pair_sections(zd, pd, gain)


def _conjugates_and_reals(values: np.ndarray) -> np.ndarray:
    """One of each complex-conjugate pair (positive imaginary part, the pair's average), then
    the real values, each group sorted by real part then size of imaginary part."""
    tol = 100 * np.finfo(np.float64).eps
    values = values[np.lexsort((np.abs(values.imag), values.real))]
    real = np.abs(values.imag) <= tol * np.abs(values)
    upper, lower = values[~real & (values.imag > 0)], values[~real & (values.imag < 0)]
    if len(upper) != len(lower):
        raise ValueError("a complex pole or zero has no conjugate")
    return np.concatenate(((upper + lower.conj()) / 2, values[real].real.astype(complex)))


def _pair_sections(z: np.ndarray, p: np.ndarray, k: float) -> np.ndarray:
    """Sections of a digital filter of equally many zeros and poles (scipy's zpk2sos, "nearest" pairing)."""
    if len(p) % 2:  # a first-order section: a pole and a zero at the origin complete it
        p, z = np.append(p, 0.0), np.append(z, 0.0)
    sos = np.zeros((len(p) // 2, 6))
    z, p = _conjugates_and_reals(z), _conjugates_and_reals(p)

    def take(values: np.ndarray, target: complex, which: str) -> tuple[complex, np.ndarray]:
        """The value nearest target (any, real or complex only), and the rest."""
        order = np.argsort(np.abs(values - target))
        if which != "any":
            real = np.isreal(values[order])
            order = order[real if which == "real" else ~real]
        return values[order[0]], np.delete(values, order[0])

    def worst(values: np.ndarray) -> int:  # the pole nearest the unit circle
        return int(np.argmin(np.abs(1 - np.abs(values))))

    for si in range(len(sos) - 1, -1, -1):
        i = worst(p)
        p1, p = p[i], np.delete(p, i)
        if np.isreal(p1) and not np.isreal(p).any():
            z1, z = take(z, p1, "real")
            sos[si] = _section([z1, 0], [p1, 0])
        elif len(p) + 1 == len(z) and not np.isreal(p1) and np.isreal(p).sum() == 1 and np.isreal(z).sum() == 1:
            # keep the last real pole and zero together: pair this complex pole with complex zeros
            z1, z = take(z, p1, "complex")
            sos[si] = _section([z1, z1.conjugate()], [p1, p1.conjugate()])
        else:
            if np.isreal(p1):
                reals = np.flatnonzero(np.isreal(p))
                j = reals[worst(p[reals])]
                p2, p = p[j], np.delete(p, j)
            else:
                p2 = p1.conjugate()
            if len(z) == 0:
                sos[si] = _section([], [p1, p2])
                continue
            z1, z = take(z, p1, "any")
            if not np.isreal(z1):
                sos[si] = _section([z1, z1.conjugate()], [p1, p2])
            elif len(z):
                z2, z = take(z, p1, "real")
                sos[si] = _section([z1, z2], [p1, p2])
            else:
                sos[si] = _section([z1], [p1, p2])
    sos[0, :3] *= k
    return sos


def _section(zeros: Sequence[complex], poles: Sequence[complex]) -> np.ndarray:
    """b0 b1 b2 a0 a1 a2 of a section with these roots (up to two each), leading coefficients 1."""

    def monic(roots: Sequence[complex]) -> np.ndarray:
        c = np.ones(1, dtype=complex)
        for r in roots:
            c = np.convolve(c, np.array([1, -r], dtype=complex))
        # the roots are a conjugate pair or real: the coefficients are real
        return np.concatenate((np.zeros(3 - len(c)), c.real))

    return np.concatenate((monic(zeros), monic(poles)))


def _sos(sos: ArrayLike) -> np.ndarray:
    s = np.asarray(sos)
    if s.dtype.kind not in "biuf":
        raise TypeError(f"sos must hold real numbers, got dtype {s.dtype}")
    s = np.ascontiguousarray(s, dtype=np.float64)
    if s.ndim != 2 or s.shape[1] != 6 or len(s) == 0:
        raise ValueError(f"sos must have shape (sections, 6), got {s.shape}")
    if not np.all(s[:, 3] == 1):
        raise ValueError("sos must have a0 = 1 in every section (column 3)")
    return s


def sosfilt_zi(sos: ArrayLike) -> np.ndarray:
    """Initial states (sections, 2) of every section for the steady state of a unit step
    (``scipy.signal.sosfilt_zi``): each section's lfilter_zi times the DC gain of the sections before it."""
    s = _sos(sos)
    zi = np.empty((len(s), 2))
    scale = 1.0
    for i, (b0, b1, b2, _, a1, a2) in enumerate(s):
        # zi = A zi + B for the section's transposed direct form II
        zi[i] = scale * np.linalg.solve(np.array([[1 + a1, -1.0], [a2, 1.0]]), [b1 - a1 * b0, b2 - a2 * b0])
        scale *= (b0 + b1 + b2) / (1 + a1 + a2)
    return zi


def sosfiltfilt(
    sos: ArrayLike,
    x: ArrayLike,
    axis: int = -1,
    padtype: str | None = "odd",
    padlen: int | None = None,
    *,
    workers: int | None = None,
) -> np.ndarray:
    """Zero-phase filtering by second-order sections, forward then backward: ``scipy.signal.sosfiltfilt``.

    The line is extended by ``padlen`` samples at each end (``padtype`` "odd":
    point-symmetric about the end sample, "even": mirrored, "constant": the
    end sample, None: no extension; default length 3 (2 sections + 1), less
    the sections' trailing zeros, as scipy), filtered forward from the steady
    state of its first sample, backward from the steady state of the last
    forward output, and cut back.  The magnitude response is the filter's
    squared, the phase zero.  Requires more samples along ``axis`` than
    ``padlen``.  NaN in a line spreads over the whole line (fill gaps first).
    float64 input gives scipy's result bit for bit; other input is converted
    to float64 first (scipy extends float32 input in float32).  ``workers``:
    threads, each taking a slab of the channels (-1: every core; None: for a
    large ``x``, every core in slabs of 64 channels at least, else one).
    """
    s = _sos(sos)
    a = _float_array(x)
    axis = _axis(a, axis)
    pad_code = _checks.choice(padtype, "padtype", _PADTYPES)
    if padtype is None:
        edge = 0
    elif padlen is None:
        edge = 3 * (2 * len(s) + 1 - min(int((s[:, 2] == 0).sum()), int((s[:, 5] == 0).sum())))
    else:
        edge = _checks.integer(padlen, "padlen", 0)
    n = a.shape[axis]
    if n <= edge:
        raise ValueError(f"the length of x along axis {axis} ({n}) must be greater than padlen, which is {edge}")
    zi = np.ascontiguousarray(sosfilt_zi(s))
    lines = _lines(a, axis)
    out = np.empty_like(lines)
    if lines.size:
        sp, zp, channels = c_array(s), c_array(zi), lines.shape[1]
        pad = edge if padtype is not None else 0
        _run_slabs(
            "mt_sosfiltfilt",
            lines,
            out,
            workers,
            lambda src, dst, width: lib.mt_sosfiltfilt(sp, len(s), zp, src, dst, n, width, channels, pad, pad_code),
            # Memory-bound, so a thread takes whole rows where it can: on (432000, 62) one thread took 62 ms of CPU,
            # two slabs of 31 channels 46-55 ms each; but whenever another task ran (on a shared machine, most of
            # the time) the pair took 84-124 ms against 60-73 ms for one thread, 564 against 127-144 ms with a
            # load on the other core.  On (108000, 248) two slabs of 124 took 45 ms of CPU each against 75 ms.
            min_width=_SLAB_MIN_CHANNELS,
        )
    return _unlines(out, a, axis)


# ---------------------------------------------------------------------------
# Winter's residual analysis


class ResidualAnalysis(NamedTuple):
    """Winter's residual analysis of each channel (see :func:`residual_cutoff`).

    ``frequencies`` (m,) the cut-offs tried (Hz); ``residuals`` (m, channels)
    the RMS difference between each channel and its filtered self there;
    ``intercept`` (channels,) the noise level, where the line fitted to the
    high-frequency residuals meets 0 Hz; ``cutoff`` (channels,) the lowest
    frequency whose residual falls to the intercept (Hz), NaN for a channel
    without noise (a constant) or whose residuals never fall that low.
    """

    frequencies: np.ndarray
    residuals: np.ndarray
    intercept: np.ndarray
    cutoff: np.ndarray


def residual_cutoff(
    x: ArrayLike,
    fs: float,
    axis: int = 0,
    *,
    order: int = 2,
    steps: int = 100,
    fit: tuple[float, float] = (0.5, 0.95),
    workers: int | None = None,
) -> ResidualAnalysis:
    """Winter's residual analysis (Biomechanics and Motor Control of Human Movement, 4th ed., 3.4.4.3).

    Each line (channel) is filtered by the zero-lag Butterworth of ``order``
    (Winter: 2, run forward and backward) at cut-offs of 1, 2, ..., steps-1
    hundredths of the Nyquist frequency fs/2; the residual at a cut-off is the
    RMS of x minus the filtered x.  Above the signal's band the residual is
    mostly noise and falls about linearly with the cut-off: a straight line
    is fitted to the residuals between ``fit[0]`` and ``fit[1]`` times the
    Nyquist frequency, its value at 0 Hz (the intercept) estimates the noise,
    and the cut-off is where the residual curve comes down to that level
    (interpolated between the cut-offs tried): the frequency where the signal
    distortion the filter would add equals the noise it would let through.
    ``fs`` is the sampling rate in Hz; the lines need more than 3 (2 sections + 1)
    samples.
    """
    a = _float_array(x)
    axis = _axis(a, axis)
    fs = float(fs)
    if not (math.isfinite(fs) and fs > 0):
        raise ValueError(f"fs must be a positive sampling rate in Hz, got {fs}")
    steps = _checks.integer(steps, "steps", 3)
    lo, hi = (float(f) for f in fit)
    if not 0 < lo < hi < 1:
        raise ValueError(f"fit must be two fractions of the Nyquist frequency, 0 < low < high < 1; got {fit!r}")
    lines = _lines(a, axis)
    nyquist = fs / 2
    frequencies = nyquist * np.arange(1, steps) / steps
    residuals = np.empty((len(frequencies), lines.shape[1]))
    for i, f in enumerate(frequencies):
        smooth = sosfiltfilt(butter_sos(order, f, fs=fs), lines, axis=0, workers=workers)
        residuals[i] = np.sqrt(np.mean((lines - smooth) ** 2, axis=0))
    band = (frequencies >= lo * nyquist) & (frequencies <= hi * nyquist)
    if band.sum() < 2:
        raise ValueError(f"fit {fit!r} holds fewer than two of the {steps - 1} cut-offs tried; widen it or add steps")
    intercept = np.polynomial.polynomial.polyfit(frequencies[band], residuals[band], 1)[0]
    cutoff = np.full(lines.shape[1], np.nan)
    for c in range(lines.shape[1]):
        r, level = residuals[:, c], intercept[c]
        below = np.flatnonzero(r <= level)
        if level <= 0 or not len(below):
            continue
        i = below[0]
        if i == 0:
            cutoff[c] = frequencies[0]
            continue
        # between the last cut-off above the level and the first at or below it
        f0, f1, r0, r1 = frequencies[i - 1], frequencies[i], r[i - 1], r[i]
        cutoff[c] = f0 + (f1 - f0) * (r0 - level) / (r0 - r1)
    shape = np.moveaxis(a, axis, 0).shape[1:]
    return ResidualAnalysis(
        frequencies, residuals.reshape((len(frequencies), *shape)), intercept.reshape(shape), cutoff.reshape(shape)
    )


# ---------------------------------------------------------------------------
# polyphase resampling


def rational_ratio(new_rate: float, old_rate: float, *, limit: int = 100_000) -> tuple[int, int]:
    """(up, down), coprime, with up / down = new_rate / old_rate.

    The rates are read as the decimals they print as, so that 119.875 to 120
    is exactly 960/959 and 120 to 29.97 is 999/4000.  Where that fraction needs
    terms above ``limit`` (the FIR filter is 20 max(up, down) + 1 taps long),
    the simplest fraction within 1e-6 of the ratio is taken: a BVH frame time
    of 0.0416667 s is 24 frames per second to that precision, so 24 to 60 is
    5/2.  ValueError when no fraction with terms up to ``limit`` is that close.
    """
    for name, rate in (("new rate", new_rate), ("old rate", old_rate)):
        if not (isinstance(rate, (int, float, np.integer, np.floating)) and math.isfinite(rate) and rate > 0):
            raise ValueError(f"the {name} must be a positive number of frames per second, got {rate!r}")
    ratio = Fraction(repr(float(new_rate))) / Fraction(repr(float(old_rate)))
    if max(ratio.numerator, ratio.denominator) <= limit:
        return ratio.numerator, ratio.denominator
    # the continued fraction's convergents, simplest first, until one is within 1e-6
    for terms in (2**k for k in range(int(math.log2(limit)) + 1)):
        near = ratio.limit_denominator(terms)
        if near and max(near.numerator, near.denominator) <= limit and abs(near / ratio - 1) <= 1e-6:
            return near.numerator, near.denominator
    raise ValueError(
        f"resampling from {float(old_rate):g} to {float(new_rate):g} frames per second needs the ratio "
        f"{ratio.numerator}/{ratio.denominator}, which makes too long a filter; give rates in a simpler ratio"
    )


def _lowpass_fir(taps: int, cutoff: float, window) -> np.ndarray:
    """scipy.signal.firwin(taps, cutoff, window=window): a windowed sinc, unit gain at 0 Hz."""
    if isinstance(window, tuple) and len(window) == 2 and window[0] == "kaiser":
        beta = float(window[1])
        win = np.kaiser(taps, beta)
    elif isinstance(window, str) and window in _WINDOWS:
        win = _WINDOWS[window](taps)
    else:
        raise ValueError(
            f"window must be ('kaiser', beta), one of {', '.join(map(repr, _WINDOWS))} "
            f"or an array of FIR coefficients; got {window!r}"
        )
    m = np.arange(taps, dtype=np.float64) - (taps - 1) / 2
    h = cutoff * np.sinc(cutoff * m) * win
    return h / np.sum(h)


def _output_len(taps: int, n_in: int, up: int, down: int) -> int:
    """Length of the full output of upfirdn."""
    return ((n_in - 1) * up + taps - 1) // down + 1


def _extension(lines: np.ndarray, rows: np.ndarray, padtype: str, cval: float) -> np.ndarray:
    """Rows ``rows`` (< 0 or >= n) of the line extended by ``padtype`` (scipy.signal.upfirdn's modes)."""
    n = len(lines)
    if padtype == "constant" or not len(rows):
        return np.full((len(rows), lines.shape[1]), cval)
    if padtype in ("line", "smooth"):
        before = rows < 0
        if padtype == "line":
            slopes = (lines[-1] - lines[0]) / (n - 1) if n > 1 else np.zeros(lines.shape[1])
        else:
            first = lines[1] - lines[0] if n > 1 else np.zeros(lines.shape[1])
            last = lines[-1] - lines[-2] if n > 1 else np.zeros(lines.shape[1])
            slopes = np.where(before[:, None], first, last)
        edge = np.where(before[:, None], lines[0], lines[-1])
        steps = np.where(before, rows, rows - (n - 1)).astype(np.float64)
        return edge + steps[:, None] * slopes
    if padtype == "antireflect":  # point reflections about both ends: a shift of 2 (n - 1) rows adds 2 (last - first)
        if n == 1:
            return np.repeat(lines, len(rows), axis=0)
        period = 2 * (n - 1)
        turns, m = np.divmod(rows, period)
        base = np.where(
            (m <= n - 1)[:, None], lines[np.minimum(m, n - 1)], 2 * lines[-1] - lines[np.abs(period - m) % n]
        )
        return base + (2 * turns)[:, None] * (lines[-1] - lines[0])
    if padtype == "antisymmetric":  # a b c d | -d -c -b -a | a b c d ...
        m = rows % (2 * n)
        return np.where((m < n)[:, None], lines[np.minimum(m, n - 1)], -lines[np.clip(2 * n - 1 - m, 0, n - 1)])
    if padtype == "edge":
        index = np.clip(rows, 0, n - 1)
    elif padtype == "wrap":
        index = rows % n
    elif padtype == "symmetric":  # d c b a | a b c d | d c b a
        m = rows % (2 * n)
        index = np.where(m < n, m, 2 * n - 1 - m)
    else:  # reflect: d c b | a b c d | c b a
        period = max(2 * n - 2, 1)
        m = rows % period
        index = np.where(m < n, m, period - m) if n > 1 else np.zeros_like(rows)
    return lines[index]


def resample_poly(
    x: ArrayLike,
    up: int,
    down: int,
    axis: int = 0,
    window=("kaiser", 5.0),
    padtype: str = "constant",
    cval: float | None = None,
    *,
    workers: int | None = None,
) -> np.ndarray:
    """x resampled by up / down along ``axis`` with a polyphase FIR filter: ``scipy.signal.resample_poly``.

    The output has ceil(n up / down) samples, sample j at input position
    j down / up.  The filter is scipy's: a low-pass at the lower of the two
    Nyquist frequencies, ``firwin(20 max(up, down) + 1, 1 / max(up, down),
    window=window)`` times up, ``window`` ("kaiser", beta), "hamming", "hann",
    "blackman", "bartlett" or "boxcar"; or ``window`` an array is the FIR
    filter itself (odd length, centred).  ``padtype`` says what the filter
    sees past the ends: "constant" (``cval``, default 0: the ends fade
    towards 0, as scipy's default), "line" (the line through the first and
    last samples continued: a constant or a straight line stays exact),
    "edge", "smooth" (each end's slope continued), "symmetric", "reflect",
    "wrap", "antisymmetric" (the mirrored line negated), "antireflect" (the
    line turned half a turn about each end sample: slopes continue, so a
    straight line stays straight), or "mean", "median", "minimum", "maximum"
    (that value subtracted before and added back after, the ends padded with
    zeros).
    """
    a = _float_array(x)
    axis = _axis(a, axis)
    up, down = _checks.integer(up, "up", 1), _checks.integer(down, "down", 1)
    _checks.choice(padtype, "padtype", (*_BACKGROUNDS, *_EXTENSIONS))
    if cval is not None and padtype != "constant":
        raise ValueError(f"cval has no effect with padtype {padtype!r}")
    g = math.gcd(up, down)
    up, down = up // g, down // g
    lines = _lines(a, axis)
    if up == down == 1:
        return _unlines(lines.copy(), a, axis)
    n = len(lines)
    n_out = -(-n * up // down)
    if isinstance(window, (list, np.ndarray)):
        h = np.asarray(window, dtype=np.float64).copy()
        if h.ndim != 1 or len(h) == 0:
            raise ValueError(f"a window given as FIR coefficients must be a non-empty 1-d array, got shape {h.shape}")
        half_len = (len(h) - 1) // 2
    else:
        half_len = 10 * max(up, down)
        h = _lowpass_fir(2 * half_len + 1, 1.0 / max(up, down), window)
    h *= up
    # scipy's alignment: zeros before the filter so that output 0 falls on input 0, and after it to fill the output
    pre = down - half_len % down
    post = 0
    skip = (half_len + pre) // down
    while _output_len(len(h) + pre + post, n, up, down) < n_out + skip:
        post += 1
    h = np.concatenate((np.zeros(pre), h, np.zeros(post)))

    background = None
    if padtype in _BACKGROUNDS and n:
        background = _BACKGROUNDS[padtype](lines, axis=0, keepdims=True)
        lines = lines - background
    extend = padtype in _EXTENSIONS and not (padtype == "constant" and not cval) and n > 0
    # the rows the filter reads before and after the line
    first = -((len(h) - 1 - skip * down) // up) if n_out else 0
    last = (skip + n_out - 1) * down // up if n_out else -1
    before = np.arange(min(first, 0), 0) if extend else np.arange(0)
    after = np.arange(n, max(last + 1, n)) if extend else np.arange(0)
    rows_before = np.ascontiguousarray(_extension(lines, before, padtype, float(cval or 0.0)))
    rows_after = np.ascontiguousarray(_extension(lines, after, padtype, float(cval or 0.0)))

    out = np.empty((n_out, lines.shape[1]))
    if out.size:
        hp, src, dst = c_array(h), c_array(lines), c_array(out)
        bp, ap = c_array(rows_before), c_array(rows_after)
        channels = lines.shape[1]
        wanted = thread_count(workers, out.size + lines.size >= _PARALLEL_MIN_VALUES)
        run_ranges(
            lambda begin, end: lib.mt_upfirdn(
                hp, len(h), up, down, src, n, channels, bp, len(before), ap, len(after), skip, begin, end, dst
            ),
            even_bounds(n_out, wanted),
            "mt_upfirdn",
        )
    if background is not None:
        out += background
    return _unlines(out, a, axis)


# ---------------------------------------------------------------------------
# gaps


class GapFill(NamedTuple):
    """The result of :func:`fill_gaps`: ``values`` (the input's shape, float64) and
    ``unfilled``, the runs of NaN left, as :func:`nan_runs` lists them."""

    values: np.ndarray
    unfilled: np.ndarray


def _runs(lines: np.ndarray) -> np.ndarray:
    """(column, first, stop) of every NaN run of the (n, channels) lines, by column then first."""
    n, channels = lines.shape
    count = ffi.new("size_t *")
    src = c_array(lines)
    check(lib.mt_nan_runs(src, n, channels, channels, ffi.NULL, 0, count), "mt_nan_runs")
    runs = np.empty((count[0], 3), dtype=np.uintp)
    if count[0]:
        check(
            lib.mt_nan_runs(src, n, channels, channels, c_array(runs, "size_t[]"), count[0], count),
            "mt_nan_runs",
        )
    runs = runs.astype(np.intp)
    return runs[np.lexsort((runs[:, 1], runs[:, 0]))]


def nan_runs(x: ArrayLike, axis: int = 0) -> np.ndarray:
    """The runs of NaN along ``axis``: an int array (runs, 3) of (column, first, stop),
    frames first .. stop-1 NaN in column ``column`` (the flat index over the other
    axes, C order), sorted by column then first frame."""
    a = _float_array(x)
    return _runs(_lines(a, _axis(a, axis)))


def fill_gaps(
    x: ArrayLike,
    max_gap: int,
    method: str = "linear",
    axis: int = 0,
    *,
    missing: ArrayLike | None = None,
    workers: int | None = None,
) -> GapFill:
    """Short runs of NaN along ``axis`` filled; the others left NaN and listed.

    A run of NaN (or of samples flagged in ``missing``, a boolean array of
    x's shape or of the axis's length, one flag per frame) is filled when it
    is at most ``max_gap`` samples long and has a sample on both sides:
    "linear" on the line between those two samples (as numpy.interp),
    "cubic" on the not-a-knot cubic spline (scipy.interpolate.CubicSpline)
    through every sample of the stretch between the runs left unfilled (or
    the ends).  Runs at the ends or longer are not invented: they stay NaN and
    are listed in ``unfilled`` (see :func:`nan_runs`).  Samples that are not
    NaN are returned unchanged.
    """
    a = _float_array(x)
    axis = _axis(a, axis)
    max_gap = _checks.integer(max_gap, "max_gap", 0)
    code = _checks.choice(method, "method", _FILL_METHODS)
    lines = _lines(a, axis)
    if missing is not None:
        flags = np.asarray(missing)
        if flags.dtype != np.bool_:
            raise TypeError(f"missing must be a boolean array, got dtype {flags.dtype}")
        if flags.shape == (a.shape[axis],):
            flags = flags[:, None]
        elif flags.shape == a.shape:
            flags = _lines(flags, axis).astype(bool)
        else:
            raise ValueError(f"missing must have x's shape {a.shape} or ({a.shape[axis]},), got {flags.shape}")
        lines = np.where(flags, np.nan, lines)
    out = np.empty_like(lines)
    if lines.size:
        n, stride = lines.shape
        _run_slabs(
            "mt_fill_gaps",
            lines,
            out,
            workers,
            lambda src, dst, channels: lib.mt_fill_gaps(src, dst, n, channels, stride, max_gap, code),
        )
    return GapFill(_unlines(out, a, axis), _runs(out))
