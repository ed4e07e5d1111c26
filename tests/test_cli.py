import re
import subprocess
import sys

import pytest

import motiontheater
from motiontheater.cli import main


def test_version(capsys):
    with pytest.raises(SystemExit) as stop:
        main(["--version"])
    assert stop.value.code == 0
    assert capsys.readouterr().out.strip() == f"motiontheater {motiontheater.__version__}"
    assert re.fullmatch(r"\d+\.\d+\.\d+.*", motiontheater.__version__)


def test_help_names_the_verbs(capsys):
    with pytest.raises(SystemExit):
        main(["--help"])
    assert "demo" in capsys.readouterr().out


def test_demo_smoothing_beats_the_noise(capsys):
    assert main(["demo", "--seconds", "2", "--size", "5"]) == 0
    out = capsys.readouterr().out
    rms = {m.group(1): float(m.group(2)) for m in re.finditer(r"^\| ([a-z, ]+) \| ([\d.]+) \|", out, re.MULTILINE)}
    assert set(rms) == {"unfiltered", "median", "mean", "binomial", "median, then binomial"}
    assert all(rms[name] < rms["unfiltered"] for name in rms if name != "unfiltered")
    assert rms["median, then binomial"] < rms["median"]


def test_bad_demo_argument_is_one_line_and_nonzero(capsys):
    assert main(["demo", "--size", "0", "--seconds", "1"]) == 2
    err = capsys.readouterr().err
    assert err.strip() == "motiontheater demo: size must be in [1, 2147483647] samples, got 0"


def test_console_script_runs_as_module():
    done = subprocess.run([sys.executable, "-m", "motiontheater", "--help"], capture_output=True, text=True, check=True)
    assert "usage: motiontheater" in done.stdout
