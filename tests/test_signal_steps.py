"""The four signal steps reached every way the registry offers: methods, command-line verbs on real
AMC and BVH files, Pipeline, TOML recipes and batch; and the kernels called from many threads."""

import concurrent.futures

import numpy as np
import pytest

import motiontheater as mt
from motiontheater.cli import main
from mtcore import signal as sg
from mtcore._cdata import c_array
from mtcore._mtcore import ffi, lib
from mtcore._status import check


@pytest.fixture(scope="module")
def cmu(data_dir):
    return data_dir / "cmu"


def read(path, asf=None):
    return mt.read_take(str(path), None if asf is None else str(asf))


def test_bands_verb_on_an_amc(cmu, tmp_path, capsys):
    out = tmp_path / "bands.amc"
    asf = cmu / "07-walk.asf"
    assert (
        main(["bands", str(cmu / "07_05-walk.amc"), "--asf", str(asf), "--gains", "1,1,1.5,1,0.5", "-o", str(out)]) == 0
    )
    assert "equalize: 517 frames" in capsys.readouterr().out
    take = read(cmu / "07_05-walk.amc", asf)
    np.testing.assert_array_equal(read(out, asf).values, take.equalize(gains=(1, 1, 1.5, 1, 0.5)).values)


def test_butterworth_verb_on_a_bvh_and_its_note(cmu, tmp_path, capsys):
    out = tmp_path / "smooth.bvh"
    assert main(["butterworth", str(cmu / "16_15.bvh"), "--cutoff", "6", "--order", "2", "-o", str(out)]) == 0
    take = read(cmu / "16_15.bvh")
    np.testing.assert_allclose(read(out).values, take.butterworth(cutoff=(6.0,), order=2).values, rtol=0, atol=1e-12)
    assert main(["butterworth", str(cmu / "16_15.bvh"), "-o", str(out)]) == 0
    assert "Winter's residual analysis chose a cut-off of" in capsys.readouterr().err
    assert main(["butterworth", str(cmu / "16_15.bvh"), "--cutoff", "90", "-o", str(tmp_path / "x.bvh")]) == 2
    assert "Nyquist" in capsys.readouterr().err
    assert not (tmp_path / "x.bvh").exists()


def test_resample_verb_on_amc_and_bvh(cmu, data_dir, tmp_path):
    amc = tmp_path / "30.amc"
    assert (
        main(
            ["resample", str(cmu / "07_05-walk.amc"), "--asf", str(cmu / "07-walk.asf"), "--rate", "30", "-o", str(amc)]
        )
        == 0
    )
    low = read(amc, cmu / "07-walk.asf")
    assert low.frame_rate == 30 and low.frames == 130
    bvh = tmp_path / "60.bvh"
    assert main(["resample", str(data_dir / "bvh" / "walk01.bvh"), "--rate", "60", "-o", str(bvh)]) == 0
    again = read(bvh)
    assert again.frame_rate == pytest.approx(60) and "Frame Time: 0.016666666666666666" in bvh.read_text()
    assert main(["resample", str(cmu / "16_15.bvh"), "--rate", "30", "--rotations", "slerp", "-o", str(bvh)]) == 0


def test_fill_gaps_and_residuals_verbs(cmu, tmp_path, capsys):
    asf = str(cmu / "07-walk.asf")
    out = tmp_path / "filled.amc"
    assert main(["fill_gaps", str(cmu / "07_05-walk.amc"), "--asf", asf, "--drop", "100:110", "-o", str(out)]) == 0
    filled = read(out, asf)
    assert not np.isnan(filled.values).any()
    long_gap = ["fill_gaps", str(cmu / "07_05-walk.amc"), "--asf", asf, "--drop", "100:200", "-o", str(out)]
    assert main(long_gap) == 2  # left missing, and NaN is not written unless asked
    assert "values are NaN (frames 100-200" in capsys.readouterr().err
    assert main([*long_gap, "--allow-nan"]) == 0
    assert "left missing: root tx frames 100-200" in capsys.readouterr().err
    csv = tmp_path / "residuals.csv"
    assert main(["residuals", str(cmu / "07_05-walk.amc"), "--asf", asf, "--joints", "lfemur", "-o", str(csv)]) == 0
    assert csv.read_text().splitlines()[1].startswith("lfemur,rx,")


def test_pipeline_recipe_and_batch(cmu, tmp_path):
    take = read(cmu / "07_05-walk.amc", cmu / "07-walk.asf")
    pipeline = (
        mt.Pipeline()
        .then("fill_gaps", drop=(100, 104))
        .then("butterworth", cutoff=(6.0,))
        .then("equalize", gains=(1.0, 1.2))
        .then("resample", rate=60)
    )
    result = pipeline.apply(take)
    expected = take.fill_gaps(drop=(100, 104)).butterworth(cutoff=(6.0,)).equalize(gains=(1.0, 1.2)).resample(rate=60)
    np.testing.assert_array_equal(result.values, expected.values)
    recipe = tmp_path / "steps.toml"
    recipe.write_text(
        '[[step]]\nrun = "butterworth"\ncutoff = [6.0]\n\n'
        '[[step]]\nrun = "bands"\ngains = [1.0, 1.2]\n\n'
        '[[step]]\nrun = "resample"\nrate = 60\n'
    )
    read_back = mt.Pipeline.read(recipe).apply(take)
    np.testing.assert_array_equal(
        read_back.values, take.butterworth(cutoff=(6.0,)).equalize(gains=(1.0, 1.2)).resample(rate=60).values
    )
    folder = tmp_path / "in"
    folder.mkdir()
    for name in ("07_05-walk.amc", "07-walk.asf"):
        (folder / name).write_bytes((cmu / name).read_bytes())
    assert (
        main(["batch", str(folder), "-o", str(tmp_path / "out"), "--recipe", str(recipe), "--jobs", "1", "--quiet"])
        == 0
    )
    done = read(tmp_path / "out" / "07_05-walk.amc", tmp_path / "out" / "07-walk.asf")
    assert done.frame_rate == 60
    np.testing.assert_array_equal(done.values, read_back.values)


def test_steps_take_a_frame_range(cmu):
    take = read(cmu / "07_05-walk.amc", cmu / "07-walk.asf")
    part = take.butterworth(cutoff=(6.0,), frames=(100, 300))
    np.testing.assert_array_equal(part.values[:99], take.values[:99])
    np.testing.assert_array_equal(part.values[300:], take.values[300:])
    assert not np.array_equal(part.values[99:300], take.values[99:300])


def test_a_step_that_changes_the_skeleton_takes_no_frame_range(cmu):
    """scale makes every length longer, the bones too: confined to frames it would scale their
    translations alone (the root leaping ten times as far for them); it takes no range, and no
    splice puts in frames of another skeleton."""
    take = read(cmu / "07_05-walk.amc", cmu / "07-walk.asf")
    with pytest.raises(ValueError, match="step 'scale' has no option 'frames'"):
        mt.Pipeline.of("scale", factor=10.0, frames=[100, 150]).apply(take)
    scaled = take.scale(factor=10.0)
    np.testing.assert_allclose(scaled.positions(), 10 * take.positions(), rtol=1e-12, atol=1e-9)
    with pytest.raises(ValueError, match="only frames can be put in"):
        take.splice(take.crop(100, 150).scale(factor=10.0))


def test_kernels_from_many_threads_equal_serial(rng):
    """cffi releases the GIL: the kernels keep no state, so concurrent calls give the serial results."""
    x = rng.standard_normal((3000, 9)).cumsum(axis=0)
    holey = x.copy()
    holey[rng.random(x.shape) < 0.05] = np.nan
    sos = sg.butter_sos(4, 0.1)
    jobs = [
        lambda: sg.equalize(x, [0.5, 1.5, 0.0]),
        lambda: sg.sosfiltfilt(sos, x, axis=0),
        lambda: sg.resample_poly(x, 5, 24),
        lambda: sg.fill_gaps(holey, 4, "cubic").values,
        lambda: sg.nan_runs(holey),
    ]
    serial = [job() for job in jobs]
    with concurrent.futures.ThreadPoolExecutor(8) as pool:
        for _ in range(3):
            for got, expected in zip(pool.map(lambda job: job(), jobs * 4), serial * 4):
                np.testing.assert_array_equal(got, expected)


def test_no_function_modifies_its_input(rng):
    x = rng.standard_normal((600, 4)).cumsum(axis=0)
    x[5, 1] = np.nan
    keep = x.copy()
    sg.equalize(x, [0.0, 2.0])
    sg.sosfiltfilt(sg.butter_sos(2, 0.2), x, axis=0)
    sg.resample_poly(x, 1, 3, padtype="line")
    sg.fill_gaps(x, 3, "cubic")
    sg.nan_runs(x)
    sg.residual_cutoff(np.nan_to_num(x), 120)
    np.testing.assert_array_equal(x, keep)


def test_kernels_check_their_arguments():
    """Python validates first; the kernels check again and answer MT_EINVAL, never crash."""
    x = np.ones((8, 2))
    out = np.empty_like(x)
    gains = np.array([0.5, 0.5, 0.5, 0.5])
    sos = np.array([[1.0, 0.0, 0.0, 1.0, 0.0, 0.0]])
    bad_sos = np.array([[1.0, 0.0, 0.0, 2.0, 0.0, 0.0]])
    zi = np.zeros((1, 2))
    count = ffi.new("size_t *")
    einval = lib.MT_EINVAL
    assert lib.mt_equalize(c_array(x), c_array(out), 8, 2, 2, 4, c_array(gains), lib.MT_MODE_NEAREST, 0.0) == einval
    assert lib.mt_equalize(c_array(x), c_array(out), 8, 2, 1, 1, c_array(gains), lib.MT_MODE_NEAREST, 0.0) == einval
    assert lib.mt_equalize(c_array(x), c_array(out), 8, 2, 2, 1, c_array(gains), 9, 0.0) == einval
    assert lib.mt_equalize(c_array(x), c_array(out), 8, 2, 2, 3, ffi.NULL, lib.MT_MODE_NEAREST, 0.0) == einval
    assert lib.mt_sosfiltfilt(c_array(bad_sos), 1, c_array(zi), c_array(x), c_array(out), 8, 2, 2, 3, 1) == einval
    assert lib.mt_sosfiltfilt(c_array(sos), 1, c_array(zi), c_array(x), c_array(out), 8, 2, 2, 8, 1) == einval
    assert lib.mt_sosfiltfilt(c_array(sos), 1, c_array(zi), c_array(x), c_array(out), 8, 2, 2, 3, 7) == einval
    assert lib.mt_sosfiltfilt(c_array(sos), 0, c_array(zi), c_array(x), c_array(out), 8, 2, 2, 3, 1) == einval
    h = np.ones(3)
    null = c_array(None)
    assert lib.mt_upfirdn(c_array(h), 3, 0, 1, c_array(x), 8, 2, null, 0, null, 0, 0, 0, 8, c_array(out)) == einval
    assert lib.mt_upfirdn(c_array(h), 3, 1, 1, c_array(x), 8, 2, null, 2, null, 0, 0, 0, 8, c_array(out)) == einval
    assert lib.mt_upfirdn(c_array(h), 0, 1, 1, c_array(x), 8, 2, null, 0, null, 0, 0, 0, 8, c_array(out)) == einval
    assert lib.mt_fill_gaps(c_array(x), c_array(out), 8, 2, 2, 3, 5) == einval
    assert lib.mt_fill_gaps(c_array(x), c_array(out), 8, 2, 1, 3, 0) == einval
    assert lib.mt_nan_runs(c_array(x), 8, 2, 2, ffi.NULL, 0, ffi.NULL) == einval
    assert lib.mt_nan_runs(c_array(x), 8, 2, 2, ffi.NULL, 4, count) == einval
    # and the status becomes a ValueError naming the call when it reaches Python
    with pytest.raises(ValueError, match="mt_sosfiltfilt: .*status -1"):
        check(einval, "mt_sosfiltfilt")
