"""Every filter against scipy.ndimage and against the slow twins in twins/filters.py."""

import itertools

import numpy as np
import pytest
import scipy.ndimage as ndi

import mtcore
from twins.filters import MODES, along_axis, correlate_line, mean_line, median_line

SHAPES = [(0,), (1,), (2,), (7,), (10,), (0, 3), (3, 1), (5, 4), (4, 9), (2, 3, 5), (3, 1, 4, 2), (2, 2, 3, 3)]
SIZES = list(range(1, 16)) + [40]
CVAL = 0.75


def origins(size):
    return sorted({-(size // 2), 0, (size - 1) // 2, (size - 1) // 4})


def tolerance(x, dtype):
    """Means may round differently from scipy: 1e-12 (float64) / 1e-5 (float32) of max |x|."""
    scale = float(np.abs(x).max()) if x.size else 1.0
    return (1e-12 if dtype == np.float64 else 1e-5) * max(scale, 1.0)


def scipy_median(x, size, axis, **kw):
    """scipy's median along one axis.

    A 1-d input is lifted to 2-d: scipy 1.15-1.17 route 1-d input through a fast
    path that reads uninitialised memory when the window overhangs the line
    (scipy issues 22250, 23075).
    """
    if x.ndim == 1:
        return ndi.median_filter(x[None, :], size=size, axes=(1,), **kw)[0]
    return ndi.median_filter(x, size=size, axes=(axis,), **kw)


def cases(rng, dtype):
    for shape in SHAPES:
        x = (rng.standard_normal(shape) * 10).astype(dtype)
        for axis in range(-len(shape), len(shape)):
            yield x, axis


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("size", SIZES)
def test_median_equals_scipy_and_twin(rng, dtype, mode, size):
    for x, axis in cases(rng, dtype):
        n = x.shape[axis]
        for origin in origins(size):
            kw = dict(mode=mode, cval=CVAL, origin=origin)
            got = mtcore.median_filter1d(x, size, axis, **kw)
            assert got.dtype == dtype and got.shape == x.shape
            if size <= n:  # where scipy's own paths agree with its documented modes
                np.testing.assert_array_equal(got, scipy_median(x, size, axis, **kw))
            if x.size <= 40:
                want = along_axis(median_line, x, axis, size, mode, float(dtype(CVAL)), origin)
                np.testing.assert_array_equal(got, want.astype(dtype))


MEANS = {
    "uniform": (
        mtcore.uniform_filter1d,
        ndi.uniform_filter1d,
        lambda line, size, *rest: mean_line(line, size, *rest),
    ),
    "binomial": (
        mtcore.binomial_filter1d,
        lambda x, size, axis, **kw: ndi.correlate1d(x, mtcore.pascal_weights(size), axis, **kw),
        lambda line, size, *rest: correlate_line(line, list(mtcore.pascal_weights(size)), *rest),
    ),
}


@pytest.mark.parametrize("name", MEANS)
@pytest.mark.parametrize("dtype", [np.float64, np.float32])
@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("size", SIZES)
def test_means_equal_scipy_and_twin(rng, name, dtype, mode, size):
    ours, theirs, twin = MEANS[name]
    for x, axis in cases(rng, dtype):
        tol = tolerance(x, dtype)
        for origin in origins(size):
            kw = dict(mode=mode, cval=CVAL, origin=origin)
            got = ours(x, size, axis, **kw)
            assert got.dtype == dtype and got.shape == x.shape
            np.testing.assert_allclose(got, theirs(x, size, axis, **kw), rtol=0, atol=tol)
            if x.size <= 40:
                want = along_axis(twin, x, axis, size, mode, CVAL, origin)
                np.testing.assert_allclose(got, want, rtol=0, atol=tol)


@pytest.mark.parametrize("size", [101, 1001])
@pytest.mark.parametrize("mode", MODES)
def test_large_windows_overhanging_short_lines(rng, mode, size):
    """Windows many times longer than the line repeat the extension pattern."""
    x = rng.standard_normal((5, 3, 23))
    for axis in (0, 2):
        for origin in (-(size // 2), 0, (size - 1) // 2):
            kw = dict(mode=mode, cval=CVAL, origin=origin)
            np.testing.assert_allclose(
                mtcore.uniform_filter1d(x, size, axis, **kw),
                ndi.uniform_filter1d(x, size, axis, **kw),
                rtol=0,
                atol=1e-12,
            )
            np.testing.assert_allclose(
                mtcore.binomial_filter1d(x, size, axis, **kw),
                ndi.correlate1d(x, mtcore.pascal_weights(size), axis, **kw),
                rtol=0,
                atol=1e-12,
            )
            line = x[1, 2] if axis == 2 else x[:, 1, 2]
            got = mtcore.median_filter1d(x, size, axis, **kw)
            got_line = got[1, 2] if axis == 2 else got[:, 1, 2]
            np.testing.assert_array_equal(got_line, median_line(list(line), size, mode, CVAL, origin))


@pytest.mark.parametrize("size", [3, 5, 7, 9, 6, 25, 200])
@pytest.mark.parametrize("shape,axis", [((1000, 62), 0), ((62, 1000), 1), ((300, 300), 0), ((5, 257, 17), 1)])
def test_realistic_shapes_against_scipy(rng, size, shape, axis):
    """Chunk boundaries (256 frames), channel blocks (256), the tile path (last axis)."""
    x = rng.standard_normal(shape)
    kw = dict(mode="nearest")
    np.testing.assert_array_equal(
        mtcore.median_filter1d(x, size, axis, **kw), ndi.median_filter(x, size=size, axes=(axis,), **kw)
    )
    np.testing.assert_allclose(
        mtcore.uniform_filter1d(x, size, axis, **kw),
        ndi.uniform_filter1d(x, size, axis, **kw),
        rtol=0,
        atol=1e-12 * np.abs(x).max(),
    )
    np.testing.assert_allclose(
        mtcore.binomial_filter1d(x, size, axis, **kw),
        ndi.correlate1d(x, mtcore.pascal_weights(size), axis, **kw),
        rtol=0,
        atol=1e-12 * np.abs(x).max(),
    )


@pytest.mark.parametrize("size", [3, 5, 7, 9])
@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_median_networks_on_every_permutation(size, dtype):
    """The selection networks are checked exhaustively: all orders, and all 0-1 inputs."""
    perms = np.array(list(itertools.permutations(range(size))), dtype=dtype).T
    got = mtcore.median_filter1d(perms, size, axis=0)
    assert np.all(got[size // 2] == size // 2)
    binary = np.array(list(itertools.product([0, 1], repeat=size)), dtype=dtype).T
    got = mtcore.median_filter1d(binary, size, axis=0)[size // 2]
    np.testing.assert_array_equal(got, np.sort(binary, axis=0)[size // 2])


def test_pascal_weights():
    np.testing.assert_array_equal(mtcore.pascal_weights(1), [1.0])
    np.testing.assert_array_equal(mtcore.pascal_weights(3), np.array([1, 2, 1]) / 4)
    np.testing.assert_array_equal(mtcore.pascal_weights(5), np.array([1, 4, 6, 4, 1]) / 16)
    np.testing.assert_array_equal(mtcore.pascal_weights(7), np.array([1, 6, 15, 20, 15, 6, 1]) / 64)
    big = mtcore.pascal_weights(2001)  # 2**2000 overflows float64; the weights must not
    assert np.all(np.isfinite(big)) and abs(big.sum() - 1.0) < 1e-12 and big[1000] == big.max()
    w = mtcore.pascal_weights(5)
    w[0] = 99.0  # the caller's copy: the cached weights stay intact
    assert mtcore.pascal_weights(5)[0] == 1 / 16
