"""Butterworth design and zero-phase filtering (mt_sosfiltfilt) against scipy.signal bit for bit and
a slow twin; Winter's residual analysis on synthetic signals; the butterworth step on motions."""

import logging

import numpy as np
import pytest
import scipy.signal as ss

import motiontheater as mt
from motiontheater.model import registry
from mtcore import signal as sg
from twins.signal import sosfilt_zi_twin, sosfiltfilt_twin

KINDS = [("low", 0.1), ("low", 0.004), ("low", 0.9), ("high", 0.05), ("high", 0.8), ("band", (0.02, 0.2))]
KINDS += [("band", (0.4, 0.45)), ("band", (0.005, 0.99))]
KINDS += [("band", (1 / 120, 1 / 30)), ("high", 1 / 600)]  # the steep ones: 0.5-2 Hz and 0.1 Hz at 120 Hz


@pytest.mark.parametrize("order", range(1, 9))
@pytest.mark.parametrize(("btype", "wn"), KINDS)
def test_butter_sos_is_scipys(order, btype, wn):
    np.testing.assert_array_equal(sg.butter_sos(order, wn, btype), ss.butter(order, wn, btype, output="sos"))


def test_butter_sos_in_hz_and_scipys_names():
    np.testing.assert_array_equal(sg.butter_sos(4, 6, fs=120), ss.butter(4, 6, fs=120, output="sos"))
    np.testing.assert_array_equal(
        sg.butter_sos(3, [1, 10], "bandpass", fs=100), ss.butter(3, [1, 10], "bandpass", fs=100, output="sos")
    )
    np.testing.assert_array_equal(sg.butter_sos(2, 0.3, "hp"), ss.butter(2, 0.3, "hp", output="sos"))


@pytest.mark.parametrize("order", range(1, 9))
@pytest.mark.parametrize(("btype", "wn"), KINDS)
def test_sosfilt_zi_is_scipys(order, btype, wn):
    sos = ss.butter(order, wn, btype, output="sos")
    np.testing.assert_array_equal(sg.sosfilt_zi(sos), ss.sosfilt_zi(sos))
    np.testing.assert_allclose(sosfilt_zi_twin(sos), ss.sosfilt_zi(sos), rtol=1e-9, atol=1e-12)


def signal(rng, frames, channels):
    t = np.arange(frames)[:, None]
    return rng.standard_normal((frames, channels)).cumsum(axis=0) + 20 * np.sin(t / 17 + np.arange(channels))


@pytest.mark.parametrize("order", range(1, 9))
@pytest.mark.parametrize(("btype", "wn"), KINDS)
def test_sosfiltfilt_is_scipys_bit_for_bit(rng, order, btype, wn):
    """The issue asks for 1e-12 relative; the same operations in the same order give equality."""
    sos = ss.butter(order, wn, btype, output="sos")
    for frames in (3 * (2 * len(sos) + 1) + 1, 511, 512, 513, 1537):
        x = signal(rng, frames, 5)
        np.testing.assert_array_equal(sg.sosfiltfilt(sos, x, axis=0), ss.sosfiltfilt(sos, x, axis=0))


@pytest.mark.parametrize("padtype", ["odd", "even", "constant", None])
@pytest.mark.parametrize("channels", [1, 2, 3, 4, 5, 17, 19, 62, 63, 64, 65, 130, 301])
def test_sosfiltfilt_padtypes_and_widths(rng, padtype, channels):
    sos = ss.butter(4, [0.05, 0.3], "band", output="sos")
    x = signal(rng, 700, channels)
    np.testing.assert_array_equal(
        sg.sosfiltfilt(sos, x, axis=0, padtype=padtype), ss.sosfiltfilt(sos, x, axis=0, padtype=padtype)
    )
    for padlen in (0, 1, 10, 699):
        np.testing.assert_array_equal(
            sg.sosfiltfilt(sos, x, axis=0, padtype=padtype, padlen=padlen),
            ss.sosfiltfilt(sos, x, axis=0, padtype=padtype, padlen=padlen),
        )


@pytest.mark.parametrize(("btype", "wn"), [("low", 0.1), ("high", 0.3), ("band", (0.1, 0.2))])
@pytest.mark.parametrize("padtype", ["odd", "even", "constant", None])
def test_sosfiltfilt_equals_its_twin(rng, btype, wn, padtype):
    sos = ss.butter(3, wn, btype, output="sos")
    x = signal(rng, 300, 3)
    expected = sosfiltfilt_twin(sos, x, padtype)
    np.testing.assert_allclose(sg.sosfiltfilt(sos, x, axis=0, padtype=padtype), expected, rtol=0, atol=1e-12 * 50)


def test_sosfiltfilt_any_axis_layout_and_dtype(rng):
    sos = ss.butter(4, 0.2, output="sos")
    x = signal(rng, 600, 6)
    expected = ss.sosfiltfilt(sos, x, axis=0)
    np.testing.assert_array_equal(sg.sosfiltfilt(sos, x.T), expected.T)  # axis=-1, scipy's default
    np.testing.assert_array_equal(sg.sosfiltfilt(sos, x.T.copy(), axis=1), expected.T)
    np.testing.assert_array_equal(sg.sosfiltfilt(sos, x.reshape(600, 2, 3), axis=0).reshape(600, 6), expected)
    np.testing.assert_array_equal(sg.sosfiltfilt(sos, x.astype(">f8"), axis=0), expected)
    np.testing.assert_array_equal(sg.sosfiltfilt(sos, x[::1, ::2], axis=0), expected[:, ::2])
    x32 = x.astype(np.float32)
    # computed in float64 from the start (scipy extends float32 input in float32 first)
    np.testing.assert_array_equal(sg.sosfiltfilt(sos, x32, axis=0), ss.sosfiltfilt(sos, x32.astype(float), axis=0))
    assert sg.sosfiltfilt(sos, x32, axis=0).dtype == np.float64
    frozen = x.copy()
    frozen.flags.writeable = False
    np.testing.assert_array_equal(sg.sosfiltfilt(sos, frozen, axis=0), expected)
    np.testing.assert_array_equal(frozen, x)
    big = rng.standard_normal((20_000, 70))
    np.testing.assert_array_equal(sg.sosfiltfilt(sos, big, axis=0), sg.sosfiltfilt(sos, big, axis=0, workers=1))
    np.testing.assert_array_equal(sg.sosfiltfilt(sos, big, axis=0, workers=3), ss.sosfiltfilt(sos, big, axis=0))


@pytest.mark.parametrize("order", [2, 4])  # one section (its tile copied out) and two
def test_sosfiltfilt_thread_slabs_of_any_width(rng, order):
    """Three threads take 57 channels as slabs of 16, 24 and 17 (the last group of quads of 17 ends at its last
    channel and borrows channels of the group before); each slab writes its own channels only."""
    sos = ss.butter(order, 0.2, output="sos")
    x = signal(rng, 3000, 57)
    np.testing.assert_array_equal(sg.sosfiltfilt(sos, x, axis=0, workers=3), ss.sosfiltfilt(sos, x, axis=0))


def test_sosfiltfilt_splits_in_slabs_of_64_channels_at_least_by_default(monkeypatch):
    """workers=None splits a large x over the cores in slabs of 64 channels at least (a memory-bound pass
    gains nothing from narrower ones); explicit workers stay as given."""
    from mtcore import _parallel

    monkeypatch.setattr(_parallel, "cpu_count", lambda: 4)
    lines = np.zeros((20_000, 256))
    assert len(sg._channel_bounds(None, lines, min_width=64)) - 1 == 4
    assert len(sg._channel_bounds(2, lines, min_width=64)) - 1 == 2
    assert len(sg._channel_bounds(None, lines[:, :130], min_width=64)) - 1 == 2
    assert len(sg._channel_bounds(None, lines[:, :62], min_width=64)) - 1 == 1
    assert len(sg._channel_bounds(5, lines[:, :62], min_width=64)) - 1 == 5
    assert len(sg._channel_bounds(None, lines[:10])) - 1 == 1  # small: one thread


def test_sosfiltfilt_keeps_scipys_nan_and_inf(rng):
    sos = ss.butter(2, 0.2, output="sos")
    x = signal(rng, 100, 2)
    x[50, 0] = np.nan
    x[10, 1] = np.inf
    np.testing.assert_array_equal(sg.sosfiltfilt(sos, x, axis=0), ss.sosfiltfilt(sos, x, axis=0))


def test_sosfiltfilt_bad_input(rng):
    sos = ss.butter(4, 0.2, output="sos")
    with pytest.raises(ValueError, match="must be greater than padlen, which is 15"):
        sg.sosfiltfilt(sos, np.ones(15))
    with pytest.raises(ValueError, match=r"shape \(sections, 6\)"):
        sg.sosfiltfilt(sos[:, :5], np.ones(100))
    bad = sos.copy()
    bad[1, 3] = 2.0
    with pytest.raises(ValueError, match="a0 = 1"):
        sg.sosfiltfilt(bad, np.ones(100))
    with pytest.raises(ValueError, match="padtype must be"):
        sg.sosfiltfilt(sos, np.ones(100), padtype="line")
    with pytest.raises(TypeError, match="real numbers"):
        sg.sosfiltfilt(sos, np.ones(100, dtype=complex))
    with pytest.raises(ValueError, match="0 < Wn < fs/2 = 60"):
        sg.butter_sos(4, 60, fs=120)
    with pytest.raises(ValueError, match="two frequencies"):
        sg.butter_sos(4, 0.2, "band")
    with pytest.raises(ValueError, match="btype must be"):
        sg.butter_sos(4, 0.2, "bandstop")
    with pytest.raises(ValueError, match="N must be at least 1"):
        sg.butter_sos(0, 0.2)


# ---------------------------------------------------------------------------
# Winter's residual analysis


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("band_edge", [3.0, 4.0, 6.0, 8.0])
def test_winter_finds_the_band_edge_of_a_noisy_signal(seed, band_edge):
    """Harmonics of 1 Hz up to the band edge, unit amplitude, plus white noise of RMS 0.6 at 120 Hz:
    the residual analysis puts the cut-off within 1 Hz of the band edge.  (Winter's cut-off balances
    distortion against noise: with less noise it moves above the edge, with more below.)"""
    rng = np.random.default_rng(seed)
    t = np.arange(1200) / 120
    clean = sum(np.sin(2 * np.pi * k * t + rng.uniform(0, 2 * np.pi)) for k in np.arange(1, band_edge + 1))
    noisy = clean + 0.6 * rng.standard_normal(len(t))
    analysis = sg.residual_cutoff(noisy, 120)
    assert abs(float(analysis.cutoff) - band_edge) < 1.0
    assert 0.5 < float(analysis.intercept) < 0.8  # the noise level, about its RMS


def test_residual_analysis_per_channel_and_constant_channels(rng):
    t = np.arange(1200) / 120
    x = np.stack([np.sin(2 * np.pi * 2 * t) + 0.3 * rng.standard_normal(1200), np.full(1200, 4.0)], axis=1)
    analysis = sg.residual_cutoff(x, 120)
    assert analysis.residuals.shape == (99, 2) and analysis.frequencies.shape == (99,)
    assert np.isfinite(analysis.cutoff[0]) and np.isnan(analysis.cutoff[1])
    np.testing.assert_allclose(analysis.frequencies[[0, -1]], [0.6, 59.4])
    with pytest.raises(ValueError, match="fit must be"):
        sg.residual_cutoff(x, 120, fit=(0.9, 0.5))


# ---------------------------------------------------------------------------
# the butterworth step on motions


@pytest.fixture(scope="module")
def take(data_dir):
    skeleton = mt.read_asf(data_dir / "cmu" / "07-walk.asf")
    return mt.read_amc(data_dir / "cmu" / "07_05-walk.amc", skeleton)


def test_butterworth_step_is_scipy_on_each_channel(take):
    out = take.butterworth(cutoff=(6.0,), order=4)
    sos = ss.butter(4, 6.0, fs=take.frame_rate, output="sos")
    column = take.columns("lfemur", "rx")[0]
    x = take.values[:, column]
    np.testing.assert_allclose(out.values[:, column], ss.sosfiltfilt(sos, x - x[0]) + x[0], rtol=0, atol=1e-9)
    band = take.butterworth(cutoff=(1.0, 8.0), kind="band", order=2)
    high = take.butterworth(cutoff=(8.0,), kind="high")
    assert not np.array_equal(band.values, high.values)


def test_butterworth_step_keeps_constants_and_other_joints(take):
    still = take.replace(values=np.tile(take.values[:1], (200, 1)))
    np.testing.assert_array_equal(still.butterworth(cutoff=(5.0,)).values, still.values)
    arms = take.butterworth(cutoff=(5.0,), joints=("lhumerus",))
    others = [c for c in range(len(take.channels)) if c not in take.columns("lhumerus")]
    np.testing.assert_array_equal(arms.values[:, others], take.values[:, others])


def test_butterworth_step_chooses_its_cutoff_by_winter(take, caplog):
    with caplog.at_level(logging.INFO, logger="motiontheater"):
        out = take.butterworth()
    report = mt.signal.residual_analysis(take)
    assert f"{report.cutoff:.3g} Hz" in caplog.text
    np.testing.assert_array_equal(out.values, take.butterworth(cutoff=(report.cutoff,)).values)
    assert len(report.channels) == len(take.channels) and 1 < report.cutoff < 30


def test_butterworth_step_errors_name_the_option(take):
    with pytest.raises(ValueError, match="cutoff: 70 Hz is not between 0 and the Nyquist frequency 60 Hz"):
        take.butterworth(cutoff=(70.0,))
    with pytest.raises(ValueError, match="cutoff: a band pass takes 2 frequencies"):
        take.butterworth(cutoff=(5.0,), kind="band")
    with pytest.raises(ValueError, match="cutoff: give the cut-off of a high pass"):
        take.butterworth(kind="high")
    with pytest.raises(ValueError, match="needs more than 15 frames; the motion has 10"):
        take.crop(1, 10).butterworth(cutoff=(5.0,))
    with pytest.raises(mt.StepError, match="order"):
        take.butterworth(cutoff=(5.0,), order=2.5)


def test_residuals_exporter_writes_each_channel(take, tmp_path):
    target = tmp_path / "residuals.csv"
    registry.lookup("residuals")(take, target)
    lines = target.read_text().splitlines()
    assert lines[0] == "joint,dof,cutoff_hz,noise"
    assert len(lines) == len(take.channels) + 2
    assert lines[-1].startswith("motion,,")
