"""Arguments in any order: options between a verb's positionals, and convert's direction from the
output's suffix."""

import shutil

import pytest

import motiontheater as mt
from motiontheater.cli import main


@pytest.fixture
def take(data_dir, tmp_path, monkeypatch):
    for name in ("01_01.amc", "01.asf"):
        shutil.copy(data_dir / "cmu" / name, tmp_path)
    monkeypatch.chdir(tmp_path)
    return tmp_path


@pytest.mark.parametrize(
    "argv",
    [
        ["median", "01_01.amc", "--size", "5", "out.amc"],
        ["median", "--size", "5", "01_01.amc", "out.amc"],
        ["median", "01_01.amc", "out.amc", "--size", "5"],
        ["filter", "01_01.amc", "--median", "5", "out.amc", "--joints", "lfemur"],
    ],
)
def test_the_output_may_follow_an_option(take, argv):
    assert main(argv) == 0
    assert mt.read_take("out.amc", "01.asf").frames == mt.read_take("01_01.amc", "01.asf").frames


def test_batch_inputs_around_options(take):
    (take / "more").mkdir()
    shutil.copy(take / "01_01.amc", take / "more" / "01_02.amc")
    shutil.copy(take / "01.asf", take / "more")
    assert main(["batch", "01_01.amc", "--median", "3", "more", "-o", "out", "--jobs", "1", "--quiet"]) == 0
    # two inputs: each mirrors under a subfolder named as its folder
    assert (take / "out" / take.name / "01_01.amc").is_file() and (take / "out" / "more" / "01_02.amc").is_file()


def test_an_unknown_option_is_reported_with_the_verbs_usage(take, capsys):
    with pytest.raises(SystemExit) as stop:
        main(["median", "01_01.amc", "--size", "5", "--sise", "3", "out.amc"])
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert "usage: motiontheater median" in err and "unrecognized arguments: --sise 3" in err


def test_convert_takes_its_direction_from_the_output(take):
    assert main(["convert", "01_01.amc", "-o", "out.bvh"]) == 0
    assert mt.read_take("out.bvh").skeleton.convention == "bvh"
    assert main(["convert", "out.bvh", "-o", "back.amc"]) == 0
    assert mt.read_take("back.amc", "back.asf").skeleton.convention == "asf"
    # the same convention as the input: written as it is, not turned into the other and refused
    assert main(["convert", "01_01.amc", "-o", "same.amc"]) == 0
    assert mt.read_take("same.amc", "01.asf").skeleton.convention == "asf"
    assert main(["convert", "out.bvh", "-o", "same.bvh"]) == 0


def test_convert_to_given_against_the_output_is_refused(take, capsys):
    assert main(["convert", "01_01.amc", "--to", "bvh", "-o", "out.amc"]) == 2
    assert "written as .bvh" in capsys.readouterr().err
