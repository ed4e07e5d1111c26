"""The thesis benchmark report: its baseline is a fair one, and the command prints the table."""

import json

import numpy as np
import pytest

from motiontheater.cli import bench, main


@pytest.mark.parametrize("kind", bench.KINDS)
@pytest.mark.parametrize("size", [1, 3, 5, 7])
def test_python_baseline_computes_what_mtcore_computes(rng, kind, size):
    x = rng.standard_normal((23, 4))
    expected = bench.OURS[kind](x, size, axis=0, mode="nearest")
    np.testing.assert_allclose(bench.python_filter(kind, x.tolist(), size), expected, rtol=0, atol=1e-12)


def test_scene_from_a_real_take(data_dir):
    import motiontheater as mt

    take = mt.read_amc(data_dir / "cmu" / "01_01.amc", mt.read_asf(data_dir / "cmu" / "01.asf"))
    scene = bench.scene_from_take(take)
    assert scene.shape == (267, 59) and scene.flags.c_contiguous  # 62 channels less the root translation
    np.testing.assert_array_equal(scene[:, 0], take.channel("root", "rx")[:267])


def test_bench_command_json(capsys, monkeypatch):
    monkeypatch.setattr(bench, "HOUR", (2000, 62))  # the report's shape, not its timing, is tested here
    assert main(["bench", "--json", "--quick"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["scene"]["shape"] == [267, 90]
    rows = report["scene"]["rows"]
    assert [(r["filter"], r["size"]) for r in rows] == [(k, s) for k in bench.KINDS for s in (3, 5, 7)]
    assert all(r["mtcore"] > 0 and r["python"] > 0 for r in rows)
    assert {(r["filter"], r["mel_2004"], r["cpp_2004"]) for r in rows if r["size"] == 3} == {
        ("mean", 1.99, 0.66),
        ("binomial", 2.05, 0.64),
        ("median", 2.08, 0.59),
    }
    assert report["hour"]["shape"] == [100, 62] and len(report["hour"]["rows"]) == 9


def test_bench_command_markdown(capsys, monkeypatch):
    monkeypatch.setattr(bench, "HOUR", (2000, 62))
    assert main(["bench", "--quick"]) == 0
    out = capsys.readouterr().out
    assert "## The thesis scene: 267 frames x 90 rotation channels = 24,030 values" in out
    assert "| median | 3 | 2.08 s | 0.59 s | 4x |" in out
    assert "## 0.83 seconds at 120 Hz: 100 frames x 62 channels" in out  # what was measured, not an hour


@pytest.mark.parametrize(
    ("frames", "heading"),
    [(432_000, "One hour"), (21_600, "3 minutes"), (864_000, "2 hours"), (7_200, "One minute"), (120, "One second")],
)
def test_the_hour_table_is_headed_by_its_length(frames, heading):
    assert bench._duration(frames / 120) == heading


def test_every_benchmark_module_is_collected():
    """The benchmarks are not run by the suite: that they still import (a renamed helper breaks
    one silently until someone measures) is checked here, by collecting them."""
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    run = subprocess.run(
        [sys.executable, "-m", "pytest", "--collect-only", "-q", "-p", "no:cacheprovider", "benchmarks"],
        cwd=root,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
