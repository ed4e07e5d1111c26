"""Takes whose files disagree with their headers (a BVH of fewer or more rows than its Frames:
line says, a last row or frame cut short): read strictly they are refused; the check reads their
whole frames, tells what is wrong (kind "header") and checks the rest, and its recipe writes
them whole."""

import re
import subprocess
import sys

import numpy as np
import pytest

import motiontheater as mt
from corpus import real_files
from motiontheater.databases import survey
from motiontheater.databases.check import check_motion
from motiontheater.editing.pipeline import Pipeline
from motiontheater.formats.table import read_take_frames

WALK = real_files("bvh/walk01.bvh")
AMC = real_files("cmu/02_01.amc")


def _bvh(tmp_path, how: str):
    """walk01.bvh (101 frames) cut at the end of a row, in the middle of one, or declaring fewer
    frames than it holds."""
    if not WALK:
        pytest.skip("the real-file corpus (../shared/data/bvh) is absent")
    data = WALK[0].read_bytes()
    rows = data[data.index(b"Frame Time") :].split(b"\n", 1)[1].splitlines(keepends=True)
    head = data[: len(data) - len(b"".join(rows))]
    if how == "rows":
        text, held, frames = head + b"".join(rows[:95]), 95, (96, 101)
    elif how == "mid-row":
        text, held, frames = head + b"".join(rows[:95]) + rows[95][:40], 95, (96, 101)
    else:
        text, held, frames = re.sub(rb"Frames:\s*101", b"Frames: 90", head) + b"".join(rows), 101, (91, 101)
    path = tmp_path / f"walk_{how}.bvh"
    path.write_bytes(text)
    return path, held, frames


@pytest.mark.parametrize("how", ["rows", "mid-row", "more"])
def test_a_bvh_at_odds_with_its_header_is_checked_and_its_recipe_writes_it_whole(tmp_path, how):
    path, held, frames = _bvh(tmp_path, how)
    with pytest.raises(mt.FormatError) as refused:
        mt.read_take(path)
    assert str(path) in str(refused.value) and "line" in str(refused.value)
    motion, cut = read_take_frames(path)
    original = mt.read_take(WALK[0])
    assert motion.frames == held and cut is not None and cut.held == held
    np.testing.assert_array_equal(motion.values, original.values[:held])
    (check,) = survey.survey(survey.plan([str(path)]), workers=1)
    header = [f for f in check.findings if f.kind == "header"]
    assert [(f.first, f.last, f.severity, f.unit) for f in header] == [(*frames, "high", "s")]
    assert header[0].size == pytest.approx((frames[1] - frames[0] + 1) / original.frame_rate)
    rest = [f for f in check.findings if f.kind != "header"]
    assert check.frames == held and rest == check_motion(motion, str(path))  # the rest of the take is checked too
    survey.write_recipes([check], tmp_path / "fixes")
    recipe = tmp_path / "fixes" / (path.name + ".toml")
    assert "whole_frames = true" in recipe.read_text()
    fixed = tmp_path / "fixed.bvh"
    subprocess.run(
        [sys.executable, "-m", "motiontheater", "apply", str(path), "--recipe", str(recipe), "-o", str(fixed)],
        check=True,
        capture_output=True,
    )
    again = mt.read_take(fixed)  # whole: read strictly
    assert again.frames == held
    np.testing.assert_allclose(again.values, original.values[:held], atol=1e-9)


def test_an_amc_cut_in_its_last_frame_is_checked_on_the_frames_before_it(tmp_path):
    if not AMC:
        pytest.skip("the real-file corpus (../shared/data/cmu) is absent")
    data = AMC[0].read_bytes()
    path = tmp_path / AMC[0].name
    path.write_bytes(data[: len(data) - 30])
    skeleton = AMC[0].with_name("02.asf")
    whole = mt.read_take(AMC[0], skeleton)
    with pytest.raises(mt.FormatError):
        mt.read_take(path, skeleton)
    (check,) = survey.survey(survey.plan([str(path)], asf=str(skeleton)), workers=1)
    header = [f for f in check.findings if f.kind == "header"]
    assert [(f.first, f.last, f.severity) for f in header] == [(whole.last_frame, whole.last_frame, "high")]
    assert check.frames == whole.frames - 1


def test_a_recipe_that_reads_whole_frames_says_so_and_reads_back():
    pipeline = Pipeline(whole_frames=True).then("median", size=3)
    text = pipeline.to_toml()
    assert text.startswith("whole_frames = true\n")
    assert Pipeline.from_toml(text) == pipeline
    with pytest.raises(mt.StepError, match="whole_frames must be true or false"):
        Pipeline.from_toml('whole_frames = "yes"')
