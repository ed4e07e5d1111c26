"""Inputs at fault get a clear error, valid inputs exact results, whatever happens around a run."""

import io
import shutil

import pytest

import motiontheater as mt
from motiontheater import batch


def test_an_amc_cut_inside_its_header_reads_as_no_frames(data_dir):
    skeleton = mt.read_asf(data_dir / "cmu" / "01.asf")
    text = (data_dir / "cmu" / "01_01.amc").read_bytes()
    body = text.index(b"\n1\r\n") if b"\n1\r\n" in text else text.index(b"\n1\n")
    for cut in (1, 10, body // 2, body):
        assert mt.read_amc(io.BytesIO(text[:cut]), skeleton).frames == 0


def test_write_asf_writes_what_read_asf_reads(tmp_path):
    """A stray "(lo hi)" line kept as another key of a bone without limits, and a bone without id."""
    text = b""":version 1.10
:name odd
:units
  length 1
  angle deg
:root
  order TX TY TZ RX RY RZ
  axis XYZ
  position 0 0 0
  orientation 0 0 0
:bonedata
  begin
    name arm
    direction 1 0 0
    length 2
    axis 0 0 0 XYZ
    dof rx ry
    (1 2)
  end
  begin
    id 7
    name hand
    direction 1 0 0
    length 1
    axis 0 0 0 XYZ
    dof rz
    limits (-10 10)
  end
:hierarchy
  begin
    root arm
    arm hand
  end
"""
    skeleton = mt.read_asf(io.BytesIO(text))
    assert skeleton.bone("arm").id is None and skeleton.bone("arm").extra == (("(1", "2)"),)
    mt.write_asf(skeleton, tmp_path / "again.asf")
    assert mt.read_asf(tmp_path / "again.asf") == skeleton


def test_a_take_that_vanishes_during_a_batch_fails_alone(data_dir, tmp_path):
    src = tmp_path / "in"
    shutil.copytree(data_dir / "cmu", src)
    jobs, settled = batch.plan_jobs([str(src)], tmp_path / "out", mt.Pipeline.of("median", size=3))
    (src / "02_02.amc").unlink()
    summary = batch.run(jobs, settled, workers=1, out=tmp_path / "out")
    assert [r.input for r in summary.failed] == [str(src / "02_02.amc")]
    assert "No such file" in summary.failed[0].error
    assert len(summary.results) == len(jobs) and sum(r.ok for r in summary.results) == len(jobs) - 1


@pytest.mark.parametrize("kind", ["median", "mean", "binomial"])
def test_a_filter_of_an_impossible_size_is_refused_at_once(data_dir, kind):
    motion = mt.read_amc(data_dir / "cmu" / "02_01.amc", mt.read_asf(data_dir / "cmu" / "02.asf"))
    with pytest.raises(ValueError):
        motion.filter(kind, 1152921504606846977)


def test_a_bvh_header_claiming_more_frames_than_the_file_can_hold_allocates_nothing(data_dir, tmp_path):
    text = (data_dir / "bvh" / "walk01.bvh").read_text()
    assert "Frames:\t101" in text
    (tmp_path / "claim.bvh").write_text(text.replace("Frames:\t101", "Frames: 100000000"))
    with pytest.raises(mt.TruncatedError, match=r"claim.bvh, line \d+: the header says 100000000 frames but the"):
        mt.read_bvh(tmp_path / "claim.bvh")
