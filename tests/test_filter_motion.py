"""Filtering whole motions: unwrapping, selected joints, edges, the filter command."""

import numpy as np
import pytest

import motiontheater as mt
from motiontheater.cli import main
from motiontheater.editing.filtering import Smoother, TakeStats


@pytest.fixture
def take(data_dir):
    return mt.read_amc(data_dir / "cmu" / "01_01.amc", mt.read_asf(data_dir / "cmu" / "01.asf"))


def wrap(x):
    return (x + 180.0) % 360.0 - 180.0


@pytest.mark.parametrize("kind", ["median", "mean", "binomial"])
def test_a_real_root_crossing_180_degrees_is_smoothed_as_the_small_step_it_is(take, kind):
    """01_01's root rx runs continuously past 180 (to 202); written wrapped into [-180, 180), as many
    exporters do, it jumps by 360.  Filtering must not see that jump."""
    column = take.columns("root", "rx")[0]
    continuous = take.values[:, column]
    assert continuous.max() > 180 and np.abs(np.diff(continuous)).max() < 90
    values = take.values.copy()
    values[:, column] = wrap(continuous)
    assert np.abs(np.diff(values[:, column])).max() > 300  # the wrapped channel jumps
    wrapped = take.replace(values=values)
    got = mt.filter_motion(wrapped, kind, size=5).channel("root", "rx")
    expected = wrap(mt.filter_motion(take, kind, size=5).channel("root", "rx"))
    near_edge = np.abs(np.abs(expected) - 180) < 1e-9  # -180 and 180 are the same angle
    np.testing.assert_allclose(got[~near_edge], expected[~near_edge], rtol=0, atol=1e-9)
    assert np.abs(got).max() <= 180


def test_179_to_minus_179_gives_values_near_180_not_0(take):
    values = take.values.copy()
    column = take.columns("lfemur", "rz")[0]
    values[:, column] = np.where(np.arange(take.frames) % 2 == 0, 179.0, -179.0)
    motion = take.replace(values=values)
    for kind in ("mean", "binomial", "median"):
        smoothed = mt.filter_motion(motion, kind, size=3).channel("lfemur", "rz")
        assert (np.abs(smoothed) > 178.9).all(), kind


def test_constant_in_constant_out(take):
    values = np.tile(take.values[100], (take.frames, 1))
    motion = take.replace(values=values)
    for kind in ("median", "mean", "binomial"):
        for size in (3, 5, 7):
            np.testing.assert_array_equal(mt.filter_motion(motion, kind, size=size).values, values)


def test_median_never_invents_values(take):
    smoothed = take.median(size=7)
    for c in range(take.values.shape[1]):
        assert np.isin(smoothed.values[:, c], take.values[:, c]).all(), take.channels[c]


def test_selected_joints_leave_every_other_channel_bit_identical(take):
    smoothed = take.binomial(size=5, joints=["lhumerus", "rhumerus", "root"], translation=False)
    changed = {take.channels[c] for c in np.where((smoothed.values != take.values).any(axis=0))[0]}
    assert changed == {(j, d) for j in ("lhumerus", "rhumerus") for d in ("rx", "ry", "rz")} | {
        ("root", d) for d in ("rx", "ry", "rz")
    }
    assert smoothed.values.tobytes() != take.values.tobytes()
    assert take.mean(size=3, joints=[]).values.tobytes() == take.values.tobytes()


def test_edges_hold_by_default_and_modes_are_configurable(take):
    channel = take.channel("lfemur", "rx")
    held = take.mean(size=5, joints=["lfemur"]).channel("lfemur", "rx")
    assert held[0] == pytest.approx((3 * channel[0] + channel[1] + channel[2]) / 5, abs=1e-12)
    reflected = take.mean(size=5, joints=["lfemur"], mode="reflect").channel("lfemur", "rx")
    assert reflected[0] == pytest.approx((2 * channel[0] + 2 * channel[1] + channel[2]) / 5, abs=1e-12)


@pytest.mark.parametrize("kind", ["median", "mean", "binomial"])
@pytest.mark.parametrize("joints", [None, ["lfemur", "lowerback"], ["rhumerus", "root"]])
def test_the_means_scratch_space_changes_no_value(take, kind, joints):
    """filter_motion lets the means work in its own unwrapped copy (scratch=True): the values are
    those of working in a new array, for every column, chosen as a run or not."""
    smoother = Smoother(take.skeleton, kind, 5, joints)
    stats = TakeStats.of(take.values)
    unwrapped, _ = smoother.prepare(take.values, None)
    kept = unwrapped.copy()
    fresh = smoother.process(unwrapped, stats)
    assert unwrapped.tobytes() == kept.tobytes()  # not scratch: left as it was
    assert smoother.process(unwrapped, stats, scratch=True).tobytes() == fresh.tobytes()
    assert mt.filter_motion(take, kind, size=5, joints=joints).values.tobytes() == fresh.tobytes()


@pytest.mark.parametrize("kind", ["median", "mean", "binomial"])
def test_input_motion_is_untouched_and_metadata_kept(take, kind):
    before = take.values.copy()
    smoothed = mt.filter_motion(take, kind, size=3)
    np.testing.assert_array_equal(take.values, before)
    assert (smoothed.frame_rate, smoothed.first_frame, smoothed.header, smoothed.line_order) == (
        take.frame_rate,
        take.first_frame,
        take.header,
        take.line_order,
    )


@pytest.mark.parametrize(
    "kind,size,joints,message",
    [
        ("gauss", 3, None, "filter kind must be one of median, mean, binomial, got 'gauss'"),
        ("median", 4, None, "filter size must be an odd number of frames"),
        ("median", 0, None, "filter size must be an odd number of frames"),
        ("mean", 3, ["lelbow"], "no bone 'lelbow'"),
    ],
)
def test_bad_arguments(take, kind, size, joints, message):
    with pytest.raises(ValueError, match=message):
        mt.filter_motion(take, kind, size=size, joints=joints)


def test_filter_command(data_dir, tmp_path, capsys):
    out = tmp_path / "smooth.amc"
    assert (
        main(
            [
                "filter",
                "--median",
                "5",
                "--joints",
                "lhumerus,rhumerus",
                str(data_dir / "cmu" / "01_01.amc"),
                "--asf",
                str(data_dir / "cmu" / "01.asf"),
                "-o",
                str(out),
            ]
        )
        == 0
    )
    assert capsys.readouterr().out.strip() == (  # with the skeleton it is read with, beside it
        f"median 5 over 2751 frames of lhumerus, rhumerus: wrote {out} and its skeleton {tmp_path / 'smooth.asf'}"
    )
    assert (tmp_path / "smooth.asf").read_bytes() == (data_dir / "cmu" / "01.asf").read_bytes()
    skeleton = mt.read_asf(data_dir / "cmu" / "01.asf")
    expected = mt.read_amc(data_dir / "cmu" / "01_01.amc", skeleton).median(size=5, joints=["lhumerus", "rhumerus"])
    assert mt.read_amc(out, skeleton).values.tobytes() == expected.values.tobytes()


def test_filter_command_finds_the_skeleton_and_writes_nothing_on_failure(data_dir, tmp_path, capsys):
    out = tmp_path / "smooth.amc"
    assert (
        main(["filter", "--mean", "3", str(data_dir / "hdm05" / "HDM_bd_squat1Reps_003_120.amc"), "-o", str(out)]) == 0
    )
    capsys.readouterr()
    bad = tmp_path / "bad.amc"
    assert (
        main(["filter", "--mean", "3", "--joints", "nosuchbone", str(data_dir / "cmu" / "01_01.amc"), "-o", str(bad)])
        == 2
    )
    assert "no bone 'nosuchbone'" in capsys.readouterr().err
    assert main(["filter", "--mean", "3", "--median", "5", str(data_dir / "cmu" / "01_01.amc"), "-o", str(bad)]) == 2
    assert "give exactly one of --median N, --mean N, --binomial N" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["smooth.amc", "smooth.asf"]


def test_filter_command_on_bvh(data_dir, tmp_path, capsys):
    out = tmp_path / "w.bvh"
    assert main(["filter", "--median", "3", str(data_dir / "bvh" / "walk01.bvh"), "-o", str(out)]) == 0
    expected = mt.read_bvh(data_dir / "bvh" / "walk01.bvh").median(size=3)
    assert mt.read_bvh(out).values.tobytes() == expected.values.tobytes()


@pytest.mark.parametrize("kind", ["median", "mean", "binomial"])
@pytest.mark.parametrize("bad", [np.inf, -np.inf, np.nan])
def test_a_bad_sample_spoils_only_the_windows_that_hold_it(take, kind, bad):
    """One inf or NaN in a rotation channel: every frame whose window does not reach it smooths as
    it would without it (the unwrap steps over it, the ranges and the means' base ignore it)."""
    size, frame, column = 7, 1000, take.columns("lfemur", "rz")[0]
    values = take.values.copy()
    values[frame, column] = bad
    spoiled = mt.filter_motion(take.replace(values=values), kind, size=size)
    clean = mt.filter_motion(take, kind, size=size)
    outside = np.r_[0 : frame - size // 2, frame + size // 2 + 1 : take.frames]
    if kind == "mean":  # its running sum is summed afresh once the bad sample leaves: the last bit may differ
        np.testing.assert_allclose(spoiled.values[outside], clean.values[outside], rtol=1e-13, atol=0)
    else:
        np.testing.assert_array_equal(spoiled.values[outside], clean.values[outside])
    others = [c for c in range(values.shape[1]) if c != column]
    np.testing.assert_array_equal(spoiled.values[:, others], clean.values[:, others])


@pytest.mark.parametrize("frames", [1, 2, 7, 300])
def test_unwrapping_in_any_chunks_equals_its_twin(frames):
    """Jumps, NaN and inf anywhere (first frames included), cut into chunks of any length."""
    from motiontheater.editing.filtering import unwrap_angles
    from twins.rotations import unwrap_angles as twin

    rng = np.random.default_rng(frames)
    raw = np.cumsum(rng.normal(0, 40, (frames, 6)), axis=0)
    raw = (raw + 180) % 360 - 180  # wrapped into [-180, 180): jumps where it crosses
    raw[rng.random(raw.shape) < 0.05] = np.nan
    raw[rng.random(raw.shape) < 0.02] = np.inf
    raw[:, 5] = 12.5  # a column that never jumps
    expected = twin(raw, 360.0)[0]
    for cut in sorted({1, 2, 5, frames}):
        state, pieces = None, []
        for start in range(0, frames, cut):
            piece, state = unwrap_angles(raw[start : start + cut], 360.0, state)
            pieces.append(piece)
        np.testing.assert_array_equal(np.concatenate(pieces), expected)
