"""Inputs at fault get a clear error, valid inputs exact results, whatever happens around a run."""

import io
import shutil
import subprocess
import sys

import numpy as np
import pytest

import motiontheater as mt
from motiontheater.databases import batch


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
    assert "no such file" in summary.failed[0].error.lower()
    assert len(summary.results) == len(jobs) and sum(r.ok for r in summary.results) == len(jobs) - 1


@pytest.mark.parametrize("kind", ["median", "mean", "binomial"])
def test_a_filter_of_an_impossible_size_is_refused_at_once(data_dir, kind):
    motion = mt.read_amc(data_dir / "cmu" / "02_01.amc", mt.read_asf(data_dir / "cmu" / "02.asf"))
    with pytest.raises(ValueError):
        mt.filter_motion(motion, kind, size=1152921504606846977)


def test_a_bvh_header_claiming_more_frames_than_the_file_can_hold_allocates_nothing(data_dir, tmp_path):
    text = (data_dir / "bvh" / "walk01.bvh").read_text()
    assert "Frames:\t101" in text
    (tmp_path / "claim.bvh").write_text(text.replace("Frames:\t101", "Frames: 100000000"))
    with pytest.raises(mt.TruncatedError, match=r"claim.bvh, line \d+: the header says 100000000 frames but the"):
        mt.read_bvh(tmp_path / "claim.bvh")


def test_a_take_that_shrinks_while_it_is_read_is_an_error_not_a_crash(data_dir, tmp_path):
    """Takes are memory-mapped: a file truncated meanwhile (SIGBUS at the first page past its new
    end) ends the read with a clear error; the process lives on, and a whole file reads as before.
    Both the reader (which copies the head through the guard) and the scanners themselves."""
    script = f"""
import mmap, os, shutil
import motiontheater as mt
from motiontheater.formats.amc import _layout, _read
from mtcore.errors import ChangedFileError
from mtcore.text import scan_frames, scan_table
original, take = {str(data_dir / "cmu" / "01_01.amc")!r}, {str(tmp_path / "t.amc")!r}
table = {str(tmp_path / "table.txt")!r}
with open(table, "w") as f:
    f.write("1.5 2 3 4 5 6\\n" * 60_000)
skeleton = mt.read_asf({str(data_dir / "cmu" / "01.asf")!r})
keys, offsets, counts = _layout(skeleton, skeleton.joint_names)
body = open(original, "rb").read().index(b"\\n1\\r\\n") + 1
calls = {{
    "reader": (original, lambda text: _read(text, take, skeleton, None, 1)),
    "frames": (original, lambda text: scan_frames(text, keys, offsets, counts, 62, start=body, workers=1)),
    "table": (table, lambda text: scan_table(text, 60_000, 6, workers=1)),
}}
for name, (source, call) in calls.items():
    for cut in (0, 100, 200_000):
        shutil.copy(source, take)
        with open(take, "rb") as f, mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ) as mapped:
            os.truncate(take, cut)
            try:
                call(mapped)
                print(name, "read")
            except ChangedFileError as e:
                print(name, str(e).split(":")[0])
shutil.copy(original, take)
print(mt.read_amc(take, skeleton).frames)
"""
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == [
        *["reader mt_copy_mapped"] * 2,  # cut inside the head the reader copies
        "reader mt_scan_frames",  # cut past it
        *["frames mt_scan_frames"] * 3,
        *["table mt_scan_table"] * 3,
        "2751",
    ], done.stdout


def test_the_error_in_a_bad_take_does_not_depend_on_the_worker_count():
    """A take scanned in pieces reports the first thing wrong in it, as one piece does: here a frame
    number out of sequence where a piece begins, and a later one inside that piece."""
    from mtcore.errors import FormatError
    from mtcore.text import _piece_count, _pieces, scan_frames

    keys, offsets, counts = [b"root", b"lfemur"], [0, 6], [6, 3]
    frame = ["{}", "root 1.5 2.5 3.5 0.1 0.2 0.3", "lfemur 10.25 -3.5 7"]
    lines = [line.format(f) for f in range(1, 60_001) for line in frame]
    whole = ("\n".join(lines) + "\n").encode()
    boundaries = [begin for begin, _ in _pieces(whole, 0, _piece_count(4, len(whole)))[1:]]
    assert boundaries, "the take must be long enough to be cut"
    for boundary in boundaries:
        at = whole[:boundary].count(b"\n")
        lines_bad = list(lines)
        lines_bad[at] = "5"
        lines_bad[at + 30] = "root 1 2 x 4 5 6"
        text = ("\n".join(lines_bad) + "\n").encode()
        errors = set()
        for workers in (1, 2, 3, 4):
            with pytest.raises(FormatError) as caught:
                scan_frames(text, keys, offsets, counts, 9, workers=workers)
            errors.add((type(caught.value), str(caught.value)))
        assert errors == {(mt.SequenceError, f"line {at + 1}: frame number 5 out of sequence: expected {at // 3 + 1}")}


def test_a_bone_of_infinite_length_along_no_direction_reads_without_a_warning(data_dir):
    """Bad input the grammar accepts (length inf, direction 0 0 0): NaN points, no numpy warning."""
    import warnings

    text = (data_dir / "cmu" / "01.asf").read_text()
    at = text.index("direction", text.index(":bonedata"))
    text = text[:at] + "direction 0 0 0" + text[text.index("\n", at) :]
    at = text.index("length", at)
    text = text[:at] + "length inf" + text[text.index("\n", at) :]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rest = mt.read_asf(io.StringIO(text)).rest_positions()
    assert np.isnan(rest[1]).all() and np.isfinite(rest[0]).all()
