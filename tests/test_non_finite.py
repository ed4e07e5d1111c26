"""No command writes NaN or inf into a motion file unless asked (--allow-nan), and a take without
numbers for its legs gets a clear error from the feet verbs, not numpy's."""

import shutil

import numpy as np
import pytest

import motiontheater as mt
from motiontheater.cli import main


@pytest.fixture
def folder(data_dir, tmp_path, monkeypatch):
    for name in ("01_01.amc", "01.asf"):
        shutil.copy(data_dir / "cmu" / name, tmp_path / name)
    monkeypatch.chdir(tmp_path)
    return tmp_path


@pytest.mark.parametrize(
    "argv",
    [
        ["fill_gaps", "01_01.amc", "--drop", "100:200", "-o", "out.amc"],  # longer than --max-gap: left missing
        ["equalize", "01_01.amc", "--gains", "1e308,1e308", "-o", "out.amc"],  # overflows to inf
    ],
    ids=["gaps left", "overflow"],
)
def test_a_result_that_is_not_all_numbers_is_refused_unless_asked(folder, capsys, argv):
    before = {p.name: p.read_bytes() for p in folder.iterdir()}
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "out.amc: " in err and "values are" in err and "--allow-nan" in err and "frames " in err, err
    assert {p.name: p.read_bytes() for p in folder.iterdir()} == before  # nothing written, inputs as they were
    assert main([*argv, "--allow-nan"]) == 0
    assert not np.isfinite(mt.read_take(folder / "out.amc", folder / "01.asf").values).all()


def test_the_message_names_the_frames_and_channels(data_dir, tmp_path):
    take = mt.read_bvh(data_dir / "bvh" / "walk01.bvh")
    values = take.values.copy()
    values[9:20, 0] = np.nan
    values[40, 5] = np.inf
    holed = take.replace(values=values)
    with pytest.raises(ValueError, match=r"12 values are NaN and inf \(frames 10-20, 41; channels Hips tx, Hips ry\)"):
        mt.write_take(holed, tmp_path / "out.bvh")
    assert not (tmp_path / "out.bvh").exists()
    mt.write_take(holed, tmp_path / "out.bvh", allow_non_finite=True)
    assert np.isnan(mt.read_bvh(tmp_path / "out.bvh").values[9:20, 0]).all()


def test_batch_reports_the_take_and_writes_nothing_of_it(folder, capsys):
    recipe = folder / "recipe.toml"
    recipe.write_text('[[step]]\nrun = "fill_gaps"\ndrop = [100, 200]\n')
    assert main(["batch", "01_01.amc", "--recipe", "recipe.toml", "-o", "out", "--quiet", "--jobs", "1"]) == 1
    assert "values are NaN" in capsys.readouterr().err
    assert not (folder / "out" / "01_01.amc").exists()
    assert (
        main(["batch", "01_01.amc", "--recipe", "recipe.toml", "-o", "out", "--quiet", "--jobs", "1", "--allow-nan"])
        == 0
    )


@pytest.mark.parametrize("verb", ["skate", "contacts", "cleanup"])
def test_feet_verbs_on_a_take_of_nan_say_so(folder, capsys, verb):
    take = mt.read_take(folder / "01_01.amc")
    mt.write_amc(take.replace(values=np.full(take.values.shape, np.nan)), folder / "01_02.amc")
    argv = [verb, "01_02.amc"] + {"skate": [], "contacts": ["-o", "c.csv"], "cleanup": ["-o", "c.amc"]}[verb]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "01_02.amc: no frame holds the legs as numbers" in err and "Singular" not in err, err  # named by the take


def test_a_number_too_large_to_write_is_read_as_infinity_and_judged_without_numpys_warnings(data_dir):
    """1e400 in a BVH is read as infinity: finding the body that carries the take (a channel held
    at it spans no number) and checking the take say what they find without a RuntimeWarning."""
    import io
    import warnings

    from motiontheater.databases.check import check_motion
    from motiontheater.model.rig import body_view

    lines = (data_dir / "bvh" / "walk01.bvh").read_text().splitlines()
    at = next(i for i, line in enumerate(lines) if line.startswith("Frame Time")) + 1
    for row in (0, 40, 41):
        values = lines[at + row].split()
        values[0 if row == 0 else 10] = "1e400"
        lines[at + row] = " ".join(values)
    whole = "\n".join(lines) + "\n"
    one = "\n".join(lines[: at - 2] + ["Frames: 1", lines[at - 1], lines[at]]) + "\n"
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        assert np.isinf(mt.read_bvh(io.BytesIO(one.encode())).values[0, 0])
        assert body_view(mt.read_bvh(io.BytesIO(one.encode()))).body
        take = mt.read_bvh(io.BytesIO(whole.encode()))
        gaps = [f for f in check_motion(take) if f.kind == "gap"]
    assert [(f.first, f.last) for f in gaps if f.first > 1] == [(41, 42)] and "infinite" in gaps[-1].detail
