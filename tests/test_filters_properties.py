"""Laws the filters obey, checked on generated data."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import array_shapes, arrays

import mtcore

MODES = ["reflect", "nearest", "mirror", "constant", "wrap"]
finite = st.floats(-1e6, 1e6, allow_nan=False, allow_subnormal=False, width=64)
data = arrays(np.float64, array_shapes(min_dims=1, max_dims=3, min_side=0, max_side=12), elements=finite)
sizes = st.integers(1, 12)


def axis_of(x, k):
    return k % x.ndim


@given(x=data, size=sizes, mode=st.sampled_from(MODES), k=st.integers(0, 2))
@settings(max_examples=200, deadline=None)
def test_median_never_invents_values(x, size, mode, k):
    axis = axis_of(x, k)
    got = mtcore.median_filter1d(x, size, axis=axis, mode=mode, cval=0.5)
    allowed = set(x.ravel().tolist()) | {0.5}
    assert set(got.ravel().tolist()) <= allowed


@given(
    value=finite,
    shape=array_shapes(min_dims=1, max_dims=3, max_side=10),
    size=sizes,
    mode=st.sampled_from(["reflect", "nearest", "mirror", "wrap"]),
)
@settings(max_examples=200, deadline=None)
def test_constant_in_constant_out(value, shape, size, mode):
    x = np.full(shape, value)
    np.testing.assert_array_equal(mtcore.median_filter1d(x, size, 0, mode=mode), x)
    for fn in (mtcore.uniform_filter1d, mtcore.binomial_filter1d):
        # atol: weights times a tiny value may underflow into subnormals
        np.testing.assert_allclose(fn(x, size, 0, mode=mode), x, rtol=1e-14, atol=1e-290)


@given(x=data, size=sizes, shift=st.integers(-20, 20), k=st.integers(0, 2))
@settings(max_examples=200, deadline=None)
def test_wrap_mode_commutes_with_rolling(x, size, shift, k):
    axis = axis_of(x, k)
    rolled_then_filtered = mtcore.median_filter1d(np.roll(x, shift, axis), size, axis, mode="wrap")
    filtered_then_rolled = np.roll(mtcore.median_filter1d(x, size, axis, mode="wrap"), shift, axis)
    np.testing.assert_array_equal(rolled_then_filtered, filtered_then_rolled)


@given(x=data, size=sizes, k=st.integers(0, 2))
@settings(max_examples=200, deadline=None)
def test_median_commutes_with_monotone_maps(x, size, k):
    """Increasing maps commute with any rank; decreasing ones swap upper and lower medians,
    which coincide only for odd sizes."""
    axis = axis_of(x, k)
    median = mtcore.median_filter1d
    np.testing.assert_array_equal(median(2.0 * x, size, axis), 2.0 * median(x, size, axis))
    odd = size | 1
    np.testing.assert_array_equal(median(-x, odd, axis), -median(x, odd, axis))


@given(slope=st.floats(-100, 100), offset=finite, n=st.integers(1, 60), half=st.integers(0, 6))
@settings(max_examples=200, deadline=None)
def test_symmetric_smoothers_keep_straight_lines(slope, offset, n, half):
    """With odd, symmetric windows a ramp is reproduced wherever the window fits."""
    size = 2 * half + 1
    x = offset + slope * np.arange(n)
    inside = slice(half, n - half) if n > 2 * half else slice(0, 0)
    for fn in (mtcore.uniform_filter1d, mtcore.binomial_filter1d, mtcore.median_filter1d):
        got = fn(x, size)
        np.testing.assert_allclose(got[inside], x[inside], rtol=1e-12, atol=1e-9 * (1 + abs(offset)))
