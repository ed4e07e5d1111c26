"""The filters' limits: sizes whose scratch would not fit, NaN and infinities in running sums,
windows far longer than the line, Pascal weights of large sizes, 64-bit integer medians."""

import math
import subprocess
import sys
import textwrap

import numpy as np
import pytest
import scipy.ndimage as ndi

import mtcore
from mtcore._mtcore import ffi, lib
from twins.filters import MODES, along_axis, counted_line, mean_line, median_line

# --- sizes whose scratch does not fit ---------------------------------------------------------


def run_isolated(code: str) -> subprocess.CompletedProcess:
    """Run code in a fresh interpreter: a heap overflow there fails this test, not the test run."""
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, timeout=300, check=False
    )


def test_c_refuses_scratch_sizes_that_overflow():
    """size 2**60 + 1 on a line as long (float32, so the array's bytes still fit in ptrdiff_t):
    2 size row pointers are 2**64 + 8 bytes, which wrapped to an 8-byte block written 2**61 times."""
    done = run_isolated(
        """
        import numpy as np
        from mtcore._mtcore import ffi, lib
        x = np.zeros(4, np.float32)
        buf = ffi.from_buffer(x)
        for kind in (lib.MT_FILTER_MEDIAN, lib.MT_FILTER_UNIFORM):
            # the tile path (scratch bytes past 2**64) and the direct path (16 channels, past memory)
            for n, inner in ((2**60 + 1, 1), (2**56, 16)):
                print(lib.mt_filter1d(kind, lib.MT_FLOAT32, buf, buf, 1, n, inner, 0, 1, n, 0, 0, 0.0, ffi.NULL))
        """
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == [str(lib.MT_ENOMEM)] * 4


def test_c_refuses_arrays_larger_than_memory_can_address():
    x = np.zeros(4)
    buf = ffi.from_buffer(x)
    n = 2**60  # 2**63 bytes of float64
    assert lib.mt_filter1d(0, lib.MT_FLOAT64, buf, buf, 1, n, 1, 0, 1, 3, 0, 0, 0.0, ffi.NULL) == lib.MT_EINVAL


@pytest.mark.parametrize("filt", [mtcore.median_filter1d, mtcore.uniform_filter1d, mtcore.binomial_filter1d])
@pytest.mark.parametrize("size", [2**31, 2**60 + 1, 2**63, 2**64 + 1])
def test_python_refuses_sizes_no_window_has(filt, size):
    with pytest.raises(
        ValueError, match=rf"^size must be in \[1, \d+\] samples( for the binomial filter .*)?, got {size}$"
    ):
        filt(np.zeros((6, 2)), size)


# --- NaN and infinities in the running sums ---------------------------------------------------

BAD = [np.nan, np.inf, -np.inf]


WINDOWS = [(mode, 5) for mode in MODES] + [("reflect", 3), ("nearest", 8), ("mirror", 40), ("wrap", 300)]


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
@pytest.mark.parametrize("mode, size", WINDOWS)
@pytest.mark.parametrize("axis", [0, 1])  # the direct path (16 channels) and the tile path
def test_a_non_finite_sample_reaches_only_the_windows_that_hold_it(rng, dtype, mode, size, axis):
    """A running sum keeps a NaN after it leaves (and inf - inf is NaN): it must be summed again
    there, not at the next 256-frame block.  Against the twin, which sums each window whole."""
    x = rng.standard_normal((700, 16)).astype(dtype)
    x[10, 1] = np.nan
    x[300, 2], x[302, 2] = np.inf, -np.inf  # both in some windows: NaN there
    x[500, 3] = np.inf
    x[::97, 4] = np.nan  # gaps of 97 frames
    x[:, 5] = np.nan  # a channel of NaN
    x[600:, 6] = -np.inf
    data = x if axis == 0 else np.ascontiguousarray(x.T)
    got = mtcore.uniform_filter1d(data, size, axis, mode=mode, cval=0.5)
    want = along_axis(mean_line, data, axis, size, mode, 0.5, 0)
    tol = 1e-5 if dtype == np.float32 else 1e-12
    np.testing.assert_allclose(got, want.astype(dtype), rtol=0, atol=tol)
    line = got[:, 1] if axis == 0 else got[1]
    assert np.isfinite(line[10 + size // 2 + 1 : 256]).all()  # the old code: NaN up to the block boundary


def test_non_finite_samples_in_windows_longer_than_the_line(rng):
    x = rng.standard_normal((9, 4))
    x[2, 0], x[4, 1], x[5, 1], x[0, 2] = np.nan, np.inf, -np.inf, np.inf
    for mode in MODES:
        for size in (10, 31, 10**6):
            got = mtcore.uniform_filter1d(x, size, 0, mode=mode, origin=-(size // 2))
            want = np.stack(
                [counted_line("uniform", list(x[:, c]), size, mode, 0.0, -(size // 2)) for c in range(4)], 1
            )
            np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)


def test_binomial_nan_stays_in_its_windows(rng):
    x = rng.standard_normal((600, 3))
    x[100, 0] = np.nan
    got = mtcore.binomial_filter1d(x, 7, 0)
    assert np.flatnonzero(np.isnan(got[:, 0])).tolist() == list(range(97, 104))


# --- windows longer than the line -------------------------------------------------------------


@pytest.mark.parametrize("size", [10**6, 10**6 + 1, 2**31 - 1])
@pytest.mark.parametrize("mode", MODES)
def test_huge_windows_on_short_lines(rng, mode, size):
    """size 10**6 on (50, 3) took 477 s (a first window built by insertion): the window's samples
    are counted instead, in time and memory that grow with the line, not the window."""
    x = rng.standard_normal((50, 3)).round(2)
    x[7, 2] = np.nan
    for origin in (-(size // 2), 0, (size - 1) // 2):
        kw = dict(mode=mode, cval=0.25, origin=origin)
        median = mtcore.median_filter1d(x, size, 0, **kw)
        mean = mtcore.uniform_filter1d(x, size, 0, **kw)
        for c in range(3):
            line = x[:, c].tolist()
            np.testing.assert_array_equal(median[:, c], counted_line("median", line, size, mode, 0.25, origin))
            np.testing.assert_allclose(mean[:, c], counted_line("uniform", line, size, mode, 0.25, origin), atol=1e-12)


def test_c_windows_beyond_any_python_limit(rng):
    """mt_filter1d itself takes any size up to PTRDIFF_MAX / 4 for the median and the mean."""
    x = rng.standard_normal(5)
    for kind, name in ((lib.MT_FILTER_MEDIAN, "median"), (lib.MT_FILTER_UNIFORM, "uniform")):
        for size in (2**40, 2**60 + 1):
            for mode, code in (("reflect", 0), ("nearest", 1), ("mirror", 2), ("constant", 3), ("wrap", 4)):
                out = np.empty(5)
                status = lib.mt_filter1d(
                    kind, lib.MT_FLOAT64, ffi.from_buffer(x), ffi.from_buffer(out), 1, 5, 1, 0, 5, size, 0, code, 0.5,
                    ffi.NULL,
                )  # fmt: skip
                assert status == lib.MT_OK
                np.testing.assert_allclose(out, counted_line(name, x.tolist(), size, mode, 0.5, 0), rtol=0, atol=1e-12)


@pytest.mark.parametrize("mode", MODES)
def test_windows_just_longer_than_the_line_against_the_twin(rng, mode):
    """At the switch from the row table to counting (size n + 1), for every shape and origin."""
    for shape, axis in (((6, 4), 0), ((2, 3, 9), 2), ((1,), 0)):
        x = rng.standard_normal(shape)
        n = shape[axis]
        for size in (n, n + 1, 2 * n + 1, 4 * n + 3):
            for origin in (-(size // 2), 0, (size - 1) // 2):
                kw = dict(mode=mode, cval=-1.5, origin=origin)
                want = along_axis(median_line, x, axis, size, mode, -1.5, origin)
                np.testing.assert_array_equal(mtcore.median_filter1d(x, size, axis, **kw), want)
                want = along_axis(mean_line, x, axis, size, mode, -1.5, origin)
                np.testing.assert_allclose(mtcore.uniform_filter1d(x, size, axis, **kw), want, rtol=0, atol=1e-12)


# --- Pascal weights of large sizes ------------------------------------------------------------


@pytest.mark.parametrize("size", [1076, 10**4, 10**4 + 1, mtcore.filters.MAX_BINOMIAL_SIZE])
def test_pascal_weights_of_large_sizes_are_exact(size):
    """From the middle outwards on integers: 12 s for size 10**4 before (about size**3)."""
    w = mtcore.pascal_weights(size)
    n = size - 1
    assert len(w) == size and (w == w[::-1]).all()
    nonzero = np.flatnonzero(w)
    first = int(nonzero[0])
    for k in (n // 2, n // 2 - 7, first, first + 1, n // 2 - (n // 2 - first) // 2):
        assert w[k] == math.comb(n, k) / 2**n, k
    assert math.comb(n, first - 1) / 2**n == 0.0  # the zeros are the weights that round to 0
    assert abs(w.sum() - 1) < 1e-12


def test_binomial_sizes_beyond_the_limit_are_refused():
    most = mtcore.filters.MAX_BINOMIAL_SIZE
    for call in (lambda: mtcore.pascal_weights(most + 1), lambda: mtcore.binomial_filter1d(np.zeros(4), 2**63)):
        with pytest.raises(
            ValueError,
            match=rf"^size must be in \[1, {most}\] samples for the binomial filter \(wider smoothing: uniform_filter1d three times; see mtcore.filters\), got \d+$",
        ):
            call()


def test_binomial_of_the_largest_size_against_scipy(rng):
    x = rng.standard_normal((40, 2))
    size = mtcore.filters.MAX_BINOMIAL_SIZE
    for mode in MODES:
        got = mtcore.binomial_filter1d(x, size, 0, mode=mode)
        np.testing.assert_allclose(got, ndi.correlate1d(x, mtcore.pascal_weights(size), 0, mode=mode), atol=1e-12)


# --- 64-bit integer medians -------------------------------------------------------------------

INT64_MAX, UINT64_MAX = 2**63 - 1, 2**64 - 1


def test_int64_medians_are_values_of_their_window():
    """Computed in float64 INT64_MAX became 2**63 and came back INT64_MIN."""
    x = np.full((2, 3), INT64_MAX, np.int64)
    x[1] = [INT64_MAX, INT64_MAX - 1, INT64_MAX - 2]
    got = mtcore.median_filter1d(x, 3, 1)
    assert got.dtype == np.int64
    np.testing.assert_array_equal(got, [[INT64_MAX] * 3, [INT64_MAX, INT64_MAX - 1, INT64_MAX - 2]])


def test_nanosecond_timestamps_are_not_rounded():
    t = np.array([1700000000123456789, 1700000000123456790, 1700000000123456791, 1700000000123456788], np.int64)
    np.testing.assert_array_equal(mtcore.median_filter1d(t, 3), ndi.median_filter(t, size=3))  # scipy's 1-d path
    np.testing.assert_array_equal(mtcore.median_filter1d(t, 3), [t[0], t[1], t[1], t[3]])


@pytest.mark.parametrize("dtype", [np.int64, np.uint64])
@pytest.mark.parametrize("mode", MODES)
def test_64_bit_medians_against_the_twin(rng, dtype, mode):
    """Values near both ends of the type, ties, every mode; cval between and beyond the values."""
    info = np.iinfo(dtype)
    base = rng.integers(info.max - 2**12, info.max, 30, dtype=dtype, endpoint=True)
    low = rng.integers(info.min, info.min + 2**12, 30, dtype=dtype, endpoint=True)
    x = np.where(rng.random(30) < 0.5, base, low).astype(dtype)
    x[5:9] = x[4]  # ties
    cvals = [0.0, float(x[3]), float(info.max), -1.5, 2.0**64, -math.inf, 7.25]
    for size in (1, 2, 3, 4, 7, 31, 64):
        for cval in cvals:
            with np.errstate(invalid="ignore"):  # a cval beyond the type, where it is the median
                got = mtcore.median_filter1d(x, size, mode=mode, cval=cval)
            assert got.dtype == dtype
            want = median_line(x.tolist(), size, mode, cval, 0)
            value = np.array([isinstance(w, int) for w in want])  # else cval is the median
            np.testing.assert_array_equal(got[value], np.array(want, dtype=object)[value].astype(dtype))
            in_range = not math.isnan(cval) and info.min <= cval <= info.max
            if in_range:
                np.testing.assert_array_equal(got[~value], np.trunc(cval))


def test_64_bit_medians_into_other_outputs(rng):
    x = np.array([3, 2**62 + 1, 2**62 + 3, -(2**62), 5], np.int64)
    np.testing.assert_array_equal(mtcore.median_filter1d(x, 3, output=np.float64), [3, 2**62 + 1, 2**62 + 1, 5, 5])
    got = mtcore.median_filter1d(x, 3, mode="constant", cval=2.5, output=np.float64)
    np.testing.assert_array_equal(got, [3, 2**62 + 1, 2**62 + 1, 5, 2.5])  # cval is the median at the end
    np.testing.assert_array_equal(
        mtcore.median_filter1d(x, 3, mode="constant", cval=2.5), [3, 2**62 + 1, 2**62 + 1, 5, 2]
    )
    out = np.zeros(5, bool)
    mtcore.median_filter1d(x - 3, 3, output=out)
    np.testing.assert_array_equal(out, [False, True, True, True, True])
    small = np.array([1, 9, 2, 8, 3], np.int64)  # within 2**53: the float64 path, the same values
    np.testing.assert_array_equal(mtcore.median_filter1d(small, 3), [1, 2, 8, 3, 3])
