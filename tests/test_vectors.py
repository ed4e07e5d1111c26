"""Lengths of 3-vectors: numpy's norm, bit for bit."""

import numpy as np
import pytest

from motiontheater.model.vectors import lengths


@pytest.mark.parametrize("shape", [(0, 3), (1, 3), (7, 3), (4, 5, 3), (2, 3, 4, 3)])
def test_lengths_are_numpys_norms_bit_for_bit(shape):
    rng = np.random.default_rng(len(shape))
    v = rng.normal(size=shape) * rng.uniform(1e-3, 1e3, shape[:-1] + (1,))
    if v.size:
        v.reshape(-1, 3)[0] = (np.nan, 1.0, 2.0)
        v.reshape(-1, 3)[-1] = (np.inf, -1.0, 0.0)
    assert np.array_equal(lengths(v), np.linalg.norm(v, axis=-1), equal_nan=True)
