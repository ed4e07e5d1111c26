"""What the command line tells on the way: Python warnings as one-line messages, and the notes of
each take of a batch named and printed above the progress bar."""

import logging
import shutil
import sys
import warnings

import pytest

from motiontheater.cli import main
from motiontheater.model.registry import register, unregister


def _warns(motion):
    warnings.warn("the toy step warns", UserWarning, stacklevel=2)
    return motion


def _notes(motion):
    logging.getLogger("motiontheater").info("the toy step notes %d frames", motion.frames)
    return motion


@pytest.fixture
def toy_steps():
    register("toy_warns", _warns, "a step that warns", frames="none")
    register("toy_notes", _notes, "a step that logs a note", frames="none")
    yield
    unregister("toy_warns")
    unregister("toy_notes")


@pytest.fixture
def takes(data_dir, tmp_path, monkeypatch):
    for name in ("01_01.amc", "01.asf", "01_01.bvh"):
        shutil.copy(data_dir / "cmu" / name, tmp_path)
    monkeypatch.chdir(tmp_path)
    return tmp_path


def test_a_warning_is_a_message(toy_steps, takes, capfd):
    assert main(["toy_warns", "01_01.amc", "-o", "out.amc"]) == 0
    err = capfd.readouterr().err
    assert "warning: the toy step warns\n" in err
    assert "UserWarning" not in err and ".py" not in err


@pytest.mark.parametrize("jobs", ["1", "2"])
def test_batch_notes_name_their_take(toy_steps, takes, capfd, jobs):
    (takes / "recipe.toml").write_text('[[step]]\nrun = "toy_notes"\n')
    argv = ["batch", "01_01.amc", "01_01.bvh", "--recipe", "recipe.toml", "-o", "out", "--jobs", jobs, "--quiet"]
    assert main(argv) == 0
    lines = capfd.readouterr().err.splitlines()
    assert sorted(lines) == ["01_01.amc: the toy step notes 2751 frames", "01_01.bvh: the toy step notes 2752 frames"]


def test_notes_print_above_the_bar(toy_steps, takes, capsys, monkeypatch):
    (takes / "recipe.toml").write_text('[[step]]\nrun = "toy_notes"\n')
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)  # as at a terminal: the bar is drawn
    argv = ["batch", "01_01.amc", "01_01.bvh", "--recipe", "recipe.toml", "-o", "out", "--jobs", "1"]
    assert main(argv) == 0
    err = capsys.readouterr().err
    note = "01_01.amc: the toy step notes 2751 frames\n"
    assert note in err and "2/2 takes" in err
    assert err.index(note) > err.index("0/2 takes")  # tqdm.write: the bar drawn, cleared, the note, the bar again
