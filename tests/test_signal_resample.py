"""Polyphase resampling (mt_upfirdn, mtcore.signal.resample_poly) against scipy.signal and a slow twin;
the resample step on real takes: rates, frame numbers, round trips, rotations without jumps."""

import numpy as np
import pytest
import scipy.signal as ss
from scipy.spatial.transform import Rotation

import motiontheater as mt
from mtcore import rotations as rot
from mtcore import signal as sg
from mtcore._cdata import c_array
from mtcore._mtcore import lib
from twins.signal import resample_poly_twin, upfirdn_twin

RATIOS = [(1, 4), (1, 2), (4, 1), (2, 1), (1, 5), (5, 24), (3, 7), (960, 959), (2, 2)]
PADTYPES = ["constant", "line", "edge", "smooth", "symmetric", "reflect", "wrap", "antisymmetric", "antireflect"]
PADTYPES += ["mean", "median", "minimum", "maximum"]


def close(a, b):
    """Within 1e-12 of the reference's magnitude."""
    assert a.shape == b.shape
    if b.size:
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-12 * max(1.0, float(np.max(np.abs(b)))))


@pytest.mark.parametrize("padtype", PADTYPES)
@pytest.mark.parametrize(("up", "down"), RATIOS)
def test_resample_poly_is_scipys(rng, up, down, padtype):
    for frames in (2, 3, 7, 30, 101, 480):
        x = rng.standard_normal((frames, 4)).cumsum(axis=0)
        close(sg.resample_poly(x, up, down, padtype=padtype), ss.resample_poly(x, up, down, padtype=padtype))


@pytest.mark.parametrize(("up", "down"), RATIOS)
def test_resample_poly_one_and_no_frames(up, down):
    for padtype in ("constant", "edge", "mean", "line"):
        x = np.array([[3.5, -1.0]])
        expected = ss.resample_poly(x, up, down, padtype=padtype) if padtype != "line" else None
        got = sg.resample_poly(x, up, down, padtype=padtype)
        assert got.shape == (-(-up // down), 2)
        if expected is not None:
            close(got, expected)
        assert sg.resample_poly(np.zeros((0, 2)), up, down, padtype=padtype).shape == (0, 2)


def test_resample_poly_windows_cval_and_fir(rng):
    x = rng.standard_normal((200, 3))
    for window in ["hamming", "hann", "blackman", "bartlett", "boxcar", ("kaiser", 8.0)]:
        close(sg.resample_poly(x, 3, 2, window=window), ss.resample_poly(x, 3, 2, window=window))
    close(sg.resample_poly(x, 3, 2, cval=2.5), ss.resample_poly(x, 3, 2, cval=2.5))
    h = ss.firwin(31, 0.3)
    close(sg.resample_poly(x, 3, 2, window=h), ss.resample_poly(x, 3, 2, window=h))
    close(sg.resample_poly(x, 3, 2, window=list(h)), ss.resample_poly(x, 3, 2, window=list(h)))


@pytest.mark.parametrize(("up", "down"), [(1, 4), (4, 1), (5, 24), (3, 2)])
@pytest.mark.parametrize("padtype", ["constant", "edge", "symmetric"])
def test_resample_poly_equals_its_twin(rng, up, down, padtype):
    x = rng.standard_normal((150, 3)).cumsum(axis=0)
    close(sg.resample_poly(x, up, down, padtype=padtype), resample_poly_twin(x, up, down, padtype))


def test_upfirdn_kernel_equals_its_twin(rng):
    """mt_upfirdn over a full output with no extension is upsample, convolve, downsample."""
    for up, down, taps, frames in [(1, 1, 5, 10), (3, 2, 11, 20), (2, 5, 7, 33), (4, 1, 81, 50), (1, 4, 81, 200)]:
        h = rng.standard_normal(taps)
        x = rng.standard_normal((frames, 3))
        expected = upfirdn_twin(h, x, up, down)
        out = np.empty_like(expected)
        status = lib.mt_upfirdn(
            c_array(h),
            taps,
            up,
            down,
            c_array(x),
            frames,
            3,
            c_array(None),
            0,
            c_array(None),
            0,
            0,
            0,
            len(out),
            c_array(out),
        )
        assert status == 0
        close(out, expected)
        close(out, ss.upfirdn(h, x, up, down, axis=0))


def test_resample_poly_any_axis_dtype_and_threads(rng):
    x = rng.standard_normal((3000, 7)).cumsum(axis=0)
    expected = ss.resample_poly(x, 1, 4)
    close(sg.resample_poly(x.T, 1, 4, axis=1), expected.T)
    close(sg.resample_poly(x.T.copy(), 1, 4, axis=-1), expected.T)
    close(sg.resample_poly(x.reshape(3000, 7, 1), 1, 4)[:, :, 0], expected)
    close(sg.resample_poly(x.astype(">f8"), 1, 4), expected)
    close(sg.resample_poly(x.astype(np.float32), 1, 4), ss.resample_poly(x.astype(np.float32).astype(float), 1, 4))
    frozen = x.copy()
    frozen.flags.writeable = False
    close(sg.resample_poly(frozen, 1, 4), expected)
    big = rng.standard_normal((50_000, 62))
    np.testing.assert_array_equal(sg.resample_poly(big, 4, 1), sg.resample_poly(big, 4, 1, workers=1))


def test_resample_poly_bad_input(rng):
    x = rng.standard_normal((20, 2))
    with pytest.raises(ValueError, match="up must be at least 1"):
        sg.resample_poly(x, 0, 1)
    with pytest.raises(ValueError, match="padtype must be one of"):
        sg.resample_poly(x, 1, 2, padtype="odd")
    with pytest.raises(ValueError, match="cval has no effect"):
        sg.resample_poly(x, 1, 2, padtype="edge", cval=1.0)
    with pytest.raises(ValueError, match="window must be"):
        sg.resample_poly(x, 1, 2, window="triangle-ish")


def test_rational_ratio():
    assert sg.rational_ratio(30, 120) == (1, 4)
    assert sg.rational_ratio(60, 120) == (1, 2)
    assert sg.rational_ratio(24, 120) == (1, 5)
    assert sg.rational_ratio(25, 120) == (5, 24)
    assert sg.rational_ratio(120, 30) == (4, 1)
    assert sg.rational_ratio(120, 119.875) == (960, 959)
    assert sg.rational_ratio(29.97, 120) == (999, 4000)
    assert sg.rational_ratio(60, 1 / 0.0416667) == (5, 2)  # a BVH's rounded frame time
    with pytest.raises(ValueError, match="positive number of frames per second"):
        sg.rational_ratio(0, 120)
    up, down = sg.rational_ratio(np.pi, 120)  # no exact ratio: the simplest within 1e-6
    assert abs(up / down / (np.pi / 120) - 1) <= 1e-6 and max(up, down) <= 100_000
    with pytest.raises(ValueError, match="too long a filter"):
        sg.rational_ratio(np.pi, 120, limit=100)


# ---------------------------------------------------------------------------
# the resample step


@pytest.fixture(scope="module")
def walk(data_dir):
    return mt.read_amc(data_dir / "cmu" / "07_05-walk.amc", mt.read_asf(data_dir / "cmu" / "07-walk.asf"))


def rotation_error_degrees(a, b):
    """Largest angle (degrees) between the joints' rotations of two motions of the same skeleton."""
    worst = 0.0
    for order, extrinsic, cols in a.skeleton.euler_groups():
        qa = rot.euler_to_quaternions(a.values[:, cols], order, extrinsic=extrinsic, degrees=True)
        qb = rot.euler_to_quaternions(b.values[:, cols], order, extrinsic=extrinsic, degrees=True)
        dot = np.clip(np.abs(np.sum(qa * qb, axis=-1)), 0, 1)
        worst = max(worst, float(np.degrees(2 * np.arccos(dot)).max()))
    return worst


@pytest.mark.parametrize("rate", [30, 60, 24, 25, 119.875, 240])
def test_resample_step_rates_and_frames(walk, rate):
    out = walk.resample(rate=rate)
    up, down = sg.rational_ratio(rate, 120)
    assert out.frame_rate == rate
    assert out.frames == (walk.frames - 1) * up // down + 1
    assert out.first_frame == walk.first_frame
    # the time span is kept: the last frame is no later than the take's
    assert (out.frames - 1) / rate <= (walk.frames - 1) / 120 + 1e-12


def test_round_trip_120_30_120_of_a_smooth_take(walk):
    """The issue's measure: a smooth take (the walk, low-passed at 6 Hz) to 30 Hz and back comes
    back within 1 mm and 0.5 degrees, every frame, ends included."""
    smooth = walk.butterworth(cutoff=(6.0,))
    back = smooth.resample(rate=30).resample(rate=120)
    assert back.frames == smooth.frames  # 517 frames: 130 at 30 Hz, 517 again
    translation = smooth.columns("root", ("tx", "ty", "tz"))
    millimetres = np.abs(back.values[:, translation] - smooth.values[:, translation]) * 1000
    assert float(millimetres.max()) * smooth.skeleton.meters_per_unit < 1.0
    assert rotation_error_degrees(back, smooth) < 0.5
    lone = [c for c, (j, d) in enumerate(smooth.channels) if d.startswith("r") and len(smooth.skeleton.dofs(j)) < 3]
    assert np.abs(back.values[:, lone] - smooth.values[:, lone]).max() < 0.5


def test_slerp_for_higher_rates_is_kept_as_an_option(walk):
    smooth = walk.butterworth(cutoff=(6.0,))
    low = smooth.resample(rate=30)
    slerped = low.resample(rate=120, rotations="slerp")
    filtered = low.resample(rate=120)
    # translations are the same either way; rotations differ, SLERP the coarser
    np.testing.assert_array_equal(slerped.values[:, :3], filtered.values[:, :3])
    assert rotation_error_degrees(slerped, smooth) > rotation_error_degrees(filtered, smooth)
    # every SLERP frame lies on the arc between the two 30 Hz frames around it
    order, _, cols = smooth.skeleton.euler_groups()[0]
    q_low = Rotation.from_euler(order, low.values[:, cols].reshape(-1, 3), degrees=True).as_quat()
    q_low = q_low.reshape(low.frames, -1, 4)
    frame = 4 * 10 + 2  # halfway between 30 Hz frames 10 and 11
    mid = Rotation.from_euler(order, slerped.values[frame, cols], degrees=True)
    a, b = Rotation.from_quat(q_low[10]), Rotation.from_quat(q_low[11])
    half = a * Rotation.from_rotvec(0.5 * (a.inv() * b).as_rotvec())
    np.testing.assert_allclose((mid.inv() * half).magnitude(), 0, atol=1e-9)


def test_constants_stay_exact(walk):
    still = walk.replace(values=np.tile(walk.values[:1], (300, 1)))
    for rate in (30, 119.875, 240, 25):
        out = still.resample(rate=rate)
        np.testing.assert_array_equal(out.values, np.tile(walk.values[:1], (out.frames, 1)))
    translation = walk.columns("root", ("tx", "ty", "tz"))
    line = walk.values.copy()
    line[:, translation] = np.arange(walk.frames)[:, None] * [0.5, 0.0, -0.25] + [1.0, 2.0, 3.0]
    out = walk.replace(values=line).resample(rate=240)
    times = np.arange(out.frames) / 2
    np.testing.assert_allclose(out.values[:, translation], times[:, None] * [0.5, 0.0, -0.25] + [1, 2, 3], atol=1e-12)


def wrapped(d):
    return (d + 180) % 360 - 180


@pytest.mark.parametrize("rate", [30, 25, 240, 119.875])
def test_no_rotation_channel_gets_a_jump(walk, rate):
    """Every rotation channel of the result follows the take's channel (low-passed at 6 Hz, so that
    the resampler has nothing to remove), interpolated at the new frames, to within a few degrees
    modulo whole turns: no Euler flip, no jump the take did not make."""
    walk = walk.butterworth(cutoff=(6.0,))
    out = walk.resample(rate=rate)
    times_in, times_out = np.arange(walk.frames) / 120, np.arange(out.frames) / rate
    for column, (joint, dof) in enumerate(walk.channels):
        if not dof.startswith("r"):
            continue
        unwrapped = np.degrees(np.unwrap(np.radians(walk.values[:, column])))
        expected = np.interp(times_out, times_in, unwrapped)
        assert np.abs(wrapped(out.values[:, column] - expected)).max() < 10, (joint, dof)
        steps = np.abs(np.diff(out.values[:, column]))
        assert np.all((steps < 45) | (steps > 315)), (joint, dof)


def test_a_joint_turning_through_180_resamples_without_flips(walk):
    """A root spinning about y through +-180 degrees and tilting: its channels stay continuous
    (modulo wraps) at every rate, whichever Euler solution the quaternions come back as."""
    values = walk.values.copy()
    t = np.arange(walk.frames) / 120
    values[:, walk.columns("root", ("rx", "ry", "rz"))] = np.stack(
        [20 * np.sin(t), wrapped(150 + 60 * t), 10 * np.cos(2 * t)], axis=1
    )
    spinning = walk.replace(values=values)
    for rate in (30, 240):
        out = spinning.resample(rate=rate)
        for dof in ("rx", "ry", "rz"):
            column = walk.columns("root", dof)[0]
            steps = np.abs(wrapped(np.diff(out.values[:, column])))
            assert steps.max() < 5, dof
        assert np.abs(out.values[:, walk.columns("root", "rx")[0]]).max() < 21


def test_bvh_frame_time_and_amc_rate_are_written(walk, data_dir, tmp_path):
    bvh = mt.read_bvh(data_dir / "cmu" / "16_15.bvh")
    out = bvh.resample(rate=60)
    mt.write_bvh(out, tmp_path / "60.bvh")
    text = (tmp_path / "60.bvh").read_text()
    assert f"Frames: {out.frames}\n" in text and "Frame Time: 0.016666666666666666" in text
    again = mt.read_bvh(tmp_path / "60.bvh")
    assert again.frame_rate == pytest.approx(60) and again.frames == out.frames
    mt.write_amc(walk.resample(rate=30), tmp_path / "30.amc")
    assert ":SAMPLES-PER-SECOND 30" in (tmp_path / "30.amc").read_text()
    assert mt.read_amc(tmp_path / "30.amc", walk.skeleton).frame_rate == 30


def test_short_motions(walk):
    assert walk.crop(1, 1).resample(rate=30).frames == 1
    one = walk.crop(5, 5).resample(rate=240)  # one frame spans no time: it stays one frame
    np.testing.assert_array_equal(one.values, walk.values[4:5])
    two = walk.crop(5, 6).resample(rate=240)
    assert two.frames == 3
    np.testing.assert_allclose(two.values[[0, 2]], walk.values[4:6], rtol=0, atol=1e-12)
    empty = walk.replace(values=np.zeros((0, len(walk.channels))))
    assert empty.resample(rate=30).frames == 0
    assert walk.crop(1, 2).resample(rate=30).frames == 1
    with pytest.raises(mt.StepError, match="frames"):
        walk.resample(rate=30, frames=(1, 10))
