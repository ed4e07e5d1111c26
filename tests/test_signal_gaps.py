"""Gap filling (mt_fill_gaps, mt_nan_runs, mtcore.signal.fill_gaps) against its twin, numpy.interp and
scipy's CubicSpline; the fill_gaps step on motions: SLERP across gaps, limits, reports."""

import logging

import numpy as np
import pytest
from scipy.interpolate import CubicSpline
from scipy.spatial.transform import Rotation, Slerp

import motiontheater as mt
from mtcore import signal as sg
from twins.signal import fill_gaps_twin, nan_runs_twin


def holes(rng, frames, channels, share):
    x = rng.standard_normal((frames, channels)).cumsum(axis=0) + 10
    x[rng.random((frames, channels)) < share] = np.nan
    return x


def same(a, b):
    np.testing.assert_allclose(a, b, rtol=1e-11, atol=1e-11, equal_nan=True)


@pytest.mark.parametrize("method", ["linear", "cubic"])
@pytest.mark.parametrize("frames", [0, 1, 2, 3, 4, 5, 8, 13, 40, 111])
def test_fill_gaps_equals_its_twin(rng, frames, method):
    for share in (0.0, 0.1, 0.3, 0.6):
        x = holes(rng, frames, 5, share)
        for max_gap in (0, 1, 2, 5, 1000):
            result = sg.fill_gaps(x, max_gap, method)
            filled, unfilled = fill_gaps_twin(x, max_gap, method)
            same(result.values, filled)
            assert result.unfilled.tolist() == [list(r) for r in unfilled]


def test_fill_gaps_against_numpy_and_scipy(rng):
    """Each filled run equals numpy.interp / scipy's CubicSpline through the stretch it lies in."""
    x = holes(rng, 400, 3, 0.15)
    x[100:160, 1] = np.nan  # a long gap: it stays, and splits the stretches of column 1
    linear = sg.fill_gaps(x, 10, "linear").values
    cubic = sg.fill_gaps(x, 10, "cubic").values
    t = np.arange(400)
    for c in range(3):
        long = [(f, s) for cc, f, s in nan_runs_twin(x) if cc == c and (s - f > 10 or f == 0 or s == 400)]
        cuts = [0] + [v for run in long for v in run] + [400]
        for lo, hi in zip(cuts[::2], cuts[1::2]):
            valid = ~np.isnan(x[lo:hi, c])
            if valid.sum() < 2:
                continue
            gaps = np.isnan(x[lo:hi, c]) & ~np.isnan(linear[lo:hi, c])
            knots, values = t[lo:hi][valid], x[lo:hi, c][valid]
            same(linear[lo:hi, c][gaps], np.interp(t[lo:hi][gaps], knots, values))
            same(cubic[lo:hi, c][gaps], CubicSpline(knots, values)(t[lo:hi][gaps]))
    assert np.isnan(linear[100:160, 1]).all() and np.isnan(cubic[100:160, 1]).all()


def test_long_splines_stay_accurate(rng):
    """The spline's tridiagonal system, eliminated without pivoting, over 20000 knots."""
    x = np.sin(np.arange(20000) / 50) * 100 + rng.standard_normal(20000)
    x[rng.random(20000) < 0.2] = np.nan
    x[[0, -1]] = 0.0
    valid = ~np.isnan(x)
    expected = CubicSpline(np.flatnonzero(valid), x[valid])(np.arange(20000))
    np.testing.assert_allclose(sg.fill_gaps(x, 10**9, "cubic").values, expected, rtol=0, atol=1e-12 * 100)


def test_valid_samples_stay_bit_identical_and_unfilled_are_listed(rng):
    x = holes(rng, 300, 4, 0.2)
    for method in ("linear", "cubic"):
        result = sg.fill_gaps(x, 3, method)
        valid = ~np.isnan(x)
        np.testing.assert_array_equal(result.values[valid], x[valid])
        left = nan_runs_twin(result.values)
        assert result.unfilled.tolist() == [list(r) for r in left]
        for c, first, stop in left:
            assert first == 0 or stop == 300 or stop - first > 3


def test_flagged_frames_axes_and_threads(rng):
    x = holes(rng, 500, 6, 0.05)
    flags = np.zeros(500, dtype=bool)
    flags[200:203] = True
    flagged = x.copy()
    flagged[200:203] = np.nan
    same(sg.fill_gaps(x, 4, missing=flags).values, sg.fill_gaps(flagged, 4).values)
    each = np.zeros_like(x, dtype=bool)
    each[10:12, 2] = True
    flagged = x.copy()
    flagged[10:12, 2] = np.nan
    same(sg.fill_gaps(x, 4, missing=each).values, sg.fill_gaps(flagged, 4).values)
    expected = sg.fill_gaps(x, 4, "cubic")
    same(sg.fill_gaps(x.T, 4, "cubic", axis=1).values, expected.values.T)
    same(sg.fill_gaps(x.reshape(500, 2, 3), 4, "cubic").values.reshape(500, 6), expected.values)
    big = holes(rng, 20_000, 64, 0.01)
    np.testing.assert_array_equal(sg.fill_gaps(big, 5, "cubic").values, sg.fill_gaps(big, 5, "cubic", workers=1).values)
    frozen = x.copy()
    frozen.flags.writeable = False
    same(sg.fill_gaps(frozen, 4).values, sg.fill_gaps(x, 4).values)
    np.testing.assert_array_equal(frozen, x)


def test_nan_runs(rng):
    x = holes(rng, 200, 7, 0.3)
    assert sg.nan_runs(x).tolist() == [list(r) for r in nan_runs_twin(x)]
    assert sg.nan_runs(np.zeros((0, 3))).shape == (0, 3)
    assert sg.nan_runs(x.T, axis=1).tolist() == [list(r) for r in nan_runs_twin(x)]


def test_fill_gaps_bad_input(rng):
    x = holes(rng, 20, 2, 0.2)
    with pytest.raises(ValueError, match="method must be"):
        sg.fill_gaps(x, 3, "spline")
    with pytest.raises(ValueError, match="max_gap must be at least 0"):
        sg.fill_gaps(x, -1)
    with pytest.raises(TypeError, match="boolean"):
        sg.fill_gaps(x, 3, missing=np.zeros(20))
    with pytest.raises(ValueError, match="missing must have"):
        sg.fill_gaps(x, 3, missing=np.zeros(19, dtype=bool))


# ---------------------------------------------------------------------------
# the fill_gaps step


@pytest.fixture(scope="module")
def walk(data_dir):
    return mt.read_amc(data_dir / "cmu" / "07_05-walk.amc", mt.read_asf(data_dir / "cmu" / "07-walk.asf"))


def test_slerp_fills_rotations_on_the_arc_between_the_keys(walk):
    """A dropped stretch of the left femur is the SLERP between the frames around it (scipy's Slerp as
    the oracle); its translation-free channels and every other frame are untouched."""
    out = walk.fill_gaps(drop=(101, 110), joints=("lfemur",))
    cols = walk.columns("lfemur")
    keys = Rotation.from_euler("xyz", walk.values[[99, 110]][:, cols], degrees=True)
    expected = Slerp([99, 110], keys)(np.arange(100, 110))
    got = Rotation.from_euler("xyz", out.values[100:110, cols], degrees=True)
    np.testing.assert_allclose((got.inv() * expected).magnitude(), 0, atol=1e-9)
    others = np.ones(walk.frames, dtype=bool)
    others[100:110] = False
    np.testing.assert_array_equal(out.values[others], walk.values[others])
    untouched = [c for c in range(len(walk.channels)) if c not in cols]
    np.testing.assert_array_equal(out.values[:, untouched], walk.values[:, untouched])


def test_linear_and_cubic_fill_each_channel(walk):
    for method in ("linear", "cubic"):
        out = walk.fill_gaps(drop=(101, 104), method=method)
        dropped = walk.values.copy()
        dropped[100:104] = np.nan
        expected = sg.fill_gaps(dropped, 10, method).values
        np.testing.assert_allclose(out.values, expected, rtol=0, atol=1e-9)


def test_gaps_across_180_degrees_take_the_short_way(walk):
    values = walk.values.copy()
    column = walk.columns("root", "ry")[0]
    values[:, column] = np.where(np.arange(walk.frames) < 100, 178.0, -178.0)
    values[95:105, column] = np.nan
    holey = walk.replace(values=values)
    for method in ("linear", "cubic", "slerp"):
        filled = holey.fill_gaps(method=method).values[95:105, column]
        assert np.all(np.abs(filled) >= 177.9), method  # through 180, not through 0


def test_long_and_edge_gaps_are_left_and_reported(walk, caplog):
    values = walk.values.copy()
    values[:3, 10] = np.nan  # at the start: no frame before it
    values[200:260, 11] = np.nan  # 0.5 s: longer than the limit
    values[300:302, 12] = np.nan  # short: filled
    holey = walk.replace(values=values)
    with caplog.at_level(logging.WARNING, logger="motiontheater"):
        out = holey.fill_gaps(max_gap=0.25)
    assert np.isnan(out.values[:3, 10]).all() and np.isnan(out.values[200:260, 11]).all()
    assert not np.isnan(out.values[300:302, 12]).any()
    gaps = mt.signal.find_gaps(out)
    assert [(g.first, g.last) for g in gaps] == [(1, 3), (201, 260)]
    assert "2 gap(s)" in caplog.text and str(gaps[1]) in caplog.text


def test_max_gap_is_in_seconds(walk):
    values = walk.values.copy()
    values[50:62, 20] = np.nan  # 12 frames = 0.1 s at 120 Hz
    holey = walk.replace(values=values)
    assert np.isnan(holey.fill_gaps(max_gap=0.09).values[50:62, 20]).all()
    assert not np.isnan(holey.fill_gaps(max_gap=0.1).values[50:62, 20]).any()
    with pytest.raises(ValueError, match="drop: frames 500:600 are not within"):
        walk.fill_gaps(drop=(500, 600))
