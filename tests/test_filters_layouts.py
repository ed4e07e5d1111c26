"""Memory layouts, dtypes, output arrays, NaN, and inputs left untouched."""

import numpy as np
import pytest
import scipy.ndimage as ndi

import mtcore

FILTERS = {
    "median": (mtcore.median_filter1d, lambda x, s, axis, **kw: ndi.median_filter(x, size=s, axes=(axis,), **kw)),
    "uniform": (mtcore.uniform_filter1d, ndi.uniform_filter1d),
    "binomial": (
        mtcore.binomial_filter1d,
        lambda x, s, axis, **kw: ndi.correlate1d(x, mtcore.pascal_weights(s), axis, **kw),
    ),
}


@pytest.fixture(params=sorted(FILTERS))
def pair(request):
    return FILTERS[request.param]


def unaligned(x):
    """A C-contiguous copy of x whose data starts one byte past an aligned address."""
    buf = np.zeros(x.nbytes + 1, np.uint8)
    y = np.frombuffer(buf.data, dtype=x.dtype, count=x.size, offset=1).reshape(x.shape)
    y[...] = x
    assert not y.flags.aligned
    return y


def layouts(x):
    yield "strided", x[::2, 1::3]
    yield "reversed", x[::-1, ::-1]
    yield "fortran", np.asfortranarray(x)
    yield "transposed", x.T
    yield "byteswapped", x.astype(x.dtype.newbyteorder())
    yield "unaligned", unaligned(x)
    ro = x.copy()
    ro.flags.writeable = False
    yield "read-only", ro


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
@pytest.mark.parametrize("size", [3, 4, 7, 10])
def test_any_layout_gives_the_contiguous_result(rng, pair, dtype, size):
    ours, theirs = pair
    x = rng.standard_normal((40, 30)).astype(dtype)
    for name, view in layouts(x):
        for axis in (0, 1):
            want = theirs(np.ascontiguousarray(view, dtype=dtype), size, axis=axis, mode="mirror")
            got = ours(view, size, axis=axis, mode="mirror")
            assert got.dtype == dtype, name
            np.testing.assert_allclose(got, want, rtol=0, atol=1e-5 if dtype == np.float32 else 1e-12)


def test_inputs_are_never_modified(rng, pair):
    ours, _ = pair
    x = rng.standard_normal((50, 20))
    x[3, 4] = np.nan
    before = x.copy()
    for axis in (0, 1):
        for mode in ("reflect", "constant"):
            ours(x, 5, axis=axis, mode=mode, cval=2.0)
            ours(x, 5, axis=axis, output=np.empty_like(x))
    np.testing.assert_array_equal(x, before)


@pytest.mark.parametrize("dtype", [np.int8, np.uint8, np.int16, np.int32, np.int64, np.uint32, np.bool_])
def test_integer_and_bool_input_behave_as_scipy(rng, pair, dtype):
    ours, theirs = pair
    x = rng.integers(-100, 100, (30, 7)).astype(dtype)
    for size in (2, 3, 5):
        for axis in (0, 1):
            got = ours(x, size, axis=axis)
            want = theirs(x, size, axis=axis)
            assert got.dtype == want.dtype == dtype
            np.testing.assert_array_equal(got, want)


def test_float16_is_computed_in_float32_and_stays_float16(rng, pair):
    ours, theirs = pair
    x = rng.standard_normal((30, 8)).astype(np.float16)
    got = ours(x, 5, axis=0)
    assert got.dtype == np.float16
    want = theirs(x.astype(np.float32), 5, axis=0).astype(np.float16)
    np.testing.assert_array_equal(got, want)


@pytest.mark.parametrize("out_dtype", [np.float64, np.float32, np.int32, np.int64])
def test_output_dtype(rng, pair, out_dtype):
    ours, theirs = pair
    x = rng.standard_normal((20, 5)) * 50
    got = ours(x, 3, axis=0, output=out_dtype)
    want = theirs(x, 3, axis=0, output=out_dtype)
    assert got.dtype == want.dtype == out_dtype
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-4 if out_dtype == np.float32 else 1e-12)


def test_output_array_is_filled_and_returned(rng, pair):
    ours, theirs = pair
    x = rng.standard_normal((20, 17))
    for out in (
        np.empty_like(x),
        np.empty(x.shape, order="F"),
        np.empty((20, 34))[:, ::2],
        np.empty(x.shape, np.float32),
    ):
        result = ours(x, 5, axis=1, output=out)
        assert result is out
        np.testing.assert_allclose(out, theirs(x, 5, axis=1, output=out.dtype), rtol=0, atol=1e-5)


def test_in_place_output(rng, pair):
    ours, theirs = pair
    x = rng.standard_normal((64, 9))
    want = theirs(x, 5, axis=0)
    y = x.copy()
    assert ours(y, 5, axis=0, output=y) is y
    np.testing.assert_allclose(y, want, rtol=0, atol=1e-12)


@pytest.mark.parametrize("size", [1, 2, 3, 4, 5, 7, 9, 11, 40])
@pytest.mark.parametrize("shape,axis", [((60, 20), 0), ((20, 60), 1)])
def test_median_window_with_nan_gives_nan(rng, size, shape, axis):
    x = rng.standard_normal(shape)
    holes = [(3, 5), (10, 11), (40, 2)]
    for i, j in holes:
        x[(i, j) if axis == 0 else (j, i)] = np.nan
    got = mtcore.median_filter1d(x, size, axis=axis, mode="nearest")
    nan_in = np.isnan(x)
    for t in range(shape[axis]):
        lo, hi = t - size // 2, t - size // 2 + size - 1  # nearest: clamp into the line
        idx = np.clip(np.arange(lo, hi + 1), 0, shape[axis] - 1)
        window_has_nan = np.take(nan_in, idx, axis=axis).any(axis=axis)
        row = np.take(got, t, axis=axis)
        np.testing.assert_array_equal(np.isnan(row), window_has_nan)


def test_nan_in_means_reaches_only_the_windows_that_hold_it(rng):
    """scipy's uniform filter carries a NaN to the end of the line (its running sum); ours does
    not, as its (and our) correlate does not."""
    x = rng.standard_normal((300, 4))
    x[7, 1] = np.nan
    for ours, _ in (FILTERS["uniform"], FILTERS["binomial"]):
        got = ours(x, 5, axis=0)
        np.testing.assert_array_equal(np.flatnonzero(np.isnan(got[:, 1])), [5, 6, 7, 8, 9])
        assert not np.isnan(np.delete(got, 1, axis=1)).any()
    assert np.isnan(FILTERS["uniform"][1](x, 5, axis=0)[:, 1]).sum() > 200


def test_infinities(rng):
    x = rng.standard_normal((12, 3))
    x[4, 0], x[5, 1] = np.inf, -np.inf
    np.testing.assert_array_equal(mtcore.median_filter1d(x, 3, axis=0), ndi.median_filter(x, size=3, axes=(0,)))


def test_lists_and_scalars_of_python(rng):
    np.testing.assert_array_equal(mtcore.median_filter1d([1, 9, 2, 8, 3], 3), [1, 2, 8, 3, 3])
    np.testing.assert_allclose(mtcore.uniform_filter1d([1.0, 2.0, 3.0], 3, mode="constant"), [1.0, 2.0, 5 / 3])


@pytest.mark.parametrize("workers", [1, 2, 3, 7, -1, None])
@pytest.mark.parametrize("shape,axis", [((5000, 62), 0), ((62, 5000), 1), ((3, 2999, 5), 1)])
def test_result_does_not_depend_on_workers(rng, pair, workers, shape, axis):
    ours, _ = pair
    x = rng.standard_normal(shape) * 1e3
    for size in (5, 300):
        whole = ours(x, size, axis=axis, workers=1)
        np.testing.assert_array_equal(ours(x, size, axis=axis, workers=workers), whole)


@pytest.mark.parametrize("workers,exc", [(0, ValueError), (-2, ValueError), (1.5, TypeError)])
def test_bad_workers(pair, workers, exc):
    ours, _ = pair
    with pytest.raises(exc, match="workers must be"):
        ours(np.zeros((10, 3)), 3, workers=workers)


def _every_parallel_call(workers):
    """The array-level calls that split work over threads, each on a small valid input."""
    from mtcore.combine import combine_frames
    from mtcore.kinematics import JointTree, forward_kinematics
    from mtcore.text import scan_table

    a = np.ones((2, 3))
    tree = JointTree(
        parent=[-1],
        order=[0],
        axis=[np.eye(3)],
        direction=[np.zeros(3)],
        segment=[np.zeros(3)],
        dof_start=[0, 0],
        dof_kind=[],
        dof_column=[],
    )
    return [
        lambda: combine_frames(a, a, [0, 1], [0, 1], [0.0, 1.0], workers=workers),
        lambda: forward_kinematics(a, tree, workers=workers),
        lambda: scan_table(b"1 2 3\n", 1, 3, workers=workers),
    ]


@pytest.mark.parametrize("workers,exc", [(0, ValueError), (-2, ValueError), (1.5, TypeError)])
def test_bad_workers_everywhere(workers, exc):
    for call in _every_parallel_call(workers):
        with pytest.raises(exc, match="workers must be"):
            call()
