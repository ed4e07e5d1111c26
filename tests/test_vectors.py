"""Lengths, spans and medians: numpy's norm, ptp and median, bit for bit."""

import warnings

import numpy as np
import pytest

from motiontheater.model.vectors import lengths, median, spans


@pytest.mark.parametrize("shape", [(0, 3), (1, 3), (7, 3), (4, 5, 3), (2, 3, 4, 3)])
def test_lengths_are_numpys_norms_bit_for_bit(shape):
    rng = np.random.default_rng(len(shape))
    v = rng.normal(size=shape) * rng.uniform(1e-3, 1e3, shape[:-1] + (1,))
    if v.size:
        v.reshape(-1, 3)[0] = (np.nan, 1.0, 2.0)
        v.reshape(-1, 3)[-1] = (np.inf, -1.0, 0.0)
    assert np.array_equal(lengths(v), np.linalg.norm(v, axis=-1), equal_nan=True)


@pytest.mark.parametrize("rows", [1, 2, 7, 3000])
def test_spans_are_numpys_ptp_bit_for_bit(rows):
    rng = np.random.default_rng(rows)
    v = rng.normal(size=(rows, 3)) * 1e3
    v[rows // 2, 1] = np.nan
    assert np.array_equal(spans(v), np.ptp(v, axis=0), equal_nan=True)
    assert np.array_equal(spans(v[::2, :]), np.ptp(v[::2], axis=0), equal_nan=True)  # a view, not contiguous


@pytest.mark.parametrize("n", [0, 1, 2, 3, 4, 5, 10, 11, 400, 401])
def test_median_is_numpys_bit_for_bit(n):
    rng = np.random.default_rng(n)
    for trial in range(40):
        x = rng.normal(size=n) * 10.0 ** rng.integers(-3, 4)
        if trial % 3 == 0:
            x = np.round(x)  # ties
        if n and trial % 4 == 1:
            x[rng.integers(n)] = np.nan
        if n > 1 and trial % 5 == 2:
            x[:2] = (np.inf, -np.inf)
        with np.errstate(invalid="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore")  # numpy warns of the mean of no numbers
            want = float(np.median(x))
        assert np.array_equal(median(x), want, equal_nan=True), (trial, x)
