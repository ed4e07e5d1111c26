"""Bad ASF/AMC input raises a FormatError subclass naming the file, the line and what was expected."""

import re

import pytest

import motiontheater as mt

ASF = b"""# a small skeleton
:version 1.10
:name tiny
:units
  mass 1.0
  length 0.45
  angle deg
:root
   order TX TY TZ RX RY RZ
   axis XYZ
   position 0 0 0
   orientation 0 0 0
:bonedata
  begin
     id 1
     name hip
     direction 0 -1 0
     length 5
     axis 0 0 0 XYZ
     dof rx ry
     limits (-90 90)
            (-inf inf)
  end
  begin
     id 2
     name knee
     direction 0 -1 0
     length 4
     axis 0 0 0 XYZ
     dof rx
  end
:hierarchy
  begin
    root hip
    hip knee
  end
"""

AMC = b""":FULLY-SPECIFIED
:DEGREES
1
root 1 2 3 4 5 6
hip 7 8
knee 9
2
root 1 2 3 4 5 6
hip 7 8
knee 9
"""


def write(tmp_path, name, data):
    path = tmp_path / name
    path.write_bytes(data)
    return path


def test_the_good_files_read(tmp_path):
    motion = mt.read_amc(write(tmp_path, "t.amc", AMC), mt.read_asf(write(tmp_path, "t.asf", ASF)))
    assert motion.frames == 2 and motion.channel("knee", "rx").tolist() == [9.0, 9.0]


def line_of(data: bytes, fragment: bytes) -> int:
    return data[: data.index(fragment)].count(b"\n") + 1


AMC_CASES = [
    # (change to the text, error class, the line it names, words of the message)
    ((b"hip 7 8\nknee 9\n2", b"hip 7\nknee 9\n2"), mt.CountError, b"hip 7\n", "bone 'hip' takes 2 value(s), found 1"),
    ((b"knee 9\n2", b"knee 9 10\n2"), mt.CountError, b"knee 9 10", "bone 'knee' takes 1 value(s), found 2"),
    (
        (b"root 1 2 3 4 5 6\nhip 7 8\nknee 9\n2", b"root 1 2 3 4 x 6\nhip 7 8\nknee 9\n2"),
        mt.NumberError,
        b"root 1 2 3 4 x",
        "expected a number as value 5 of bone 'root', found 'x'",
    ),
    ((b"knee 9\n2", b"ankle 3\n2"), mt.UnknownNameError, b"ankle", "unknown bone 'ankle'"),
    ((b"knee 9\n2", b"knee 9\nknee 10\n2"), mt.DuplicateError, b"knee 10", "bone 'knee' appears twice in frame 1"),
    ((b"knee 9\n2", b"2"), mt.MissingError, b"2\n", "frame 1 has no line for bone 'knee'"),
    ((b"\n2\n", b"\n3\n"), mt.SequenceError, b"3\n", "frame number 3 out of sequence: expected 2"),
    (
        (b":DEGREES\n1\n", b":DEGREES\nroot 1 2 3 4 5 6\n"),
        mt.SequenceError,
        b"root 1 2 3 4 5 6\nroot",
        "expected a frame number, found 'root 1 2 3 4 5 6'",
    ),
]


@pytest.mark.parametrize(
    "change,error,where,words", AMC_CASES, ids=[c[1].__name__ + str(i) for i, c in enumerate(AMC_CASES)]
)
def test_bad_amc(tmp_path, change, error, where, words):
    bad = AMC.replace(*change, 1)
    assert bad != AMC
    skeleton = mt.read_asf(write(tmp_path, "t.asf", ASF))
    path = write(tmp_path, "bad.amc", bad)
    with pytest.raises(error) as caught:
        mt.read_amc(path, skeleton)
    line = line_of(bad, where) if where != b"2\n" else bad.count(b"\n", 0, bad.rindex(b"\n2\n") + 1) + 1
    assert str(caught.value).startswith(f"{path}, line {line}: {words}")
    assert isinstance(caught.value, mt.FormatError) and caught.value.line == line


def test_truncated_amc(tmp_path):
    skeleton = mt.read_asf(write(tmp_path, "t.asf", ASF))
    for cut in range(len(AMC) - 25, len(AMC) - 1):
        path = write(tmp_path, "cut.amc", AMC[:cut])
        with pytest.raises(mt.FormatError, match=rf"^{re.escape(str(path))}, line \d+: ") as caught:
            mt.read_amc(path, skeleton)
        assert isinstance(caught.value, mt.TruncatedError), caught.value
        assert str(caught.value).endswith("(the file ends there: truncated?)")
    path = write(tmp_path, "cut.amc", AMC[: AMC.rindex(b"knee")])
    with pytest.raises(mt.TruncatedError, match=r"line 10: frame 2 has no line for bone 'knee' \(the file ends there"):
        mt.read_amc(path, skeleton)


def test_amc_of_another_skeleton(data_dir, tmp_path):
    skeleton = mt.read_asf(data_dir / "cmu" / "01.asf")
    with pytest.raises(
        mt.UnknownNameError, match=r"test.amc, line 4: unknown bone 'Head'; expected one of: root, lhipjoint"
    ):
        mt.read_amc(data_dir / "edge" / "test.amc", skeleton)
    tiny = mt.read_asf(write(tmp_path, "t.asf", ASF))
    with pytest.raises(mt.UnknownNameError, match=r"01_01.amc, line 7: unknown bone 'lowerback'"):
        mt.read_amc(data_dir / "cmu" / "01_01.amc", tiny)


ASF_CASES = [
    ((b"    hip knee\n", b""), mt.HierarchyError, b":hierarchy", "bone 'knee' has no parent in the hierarchy"),
    (
        (b"     name knee", b"     name hip"),
        mt.DuplicateError,
        b"     name hip\n     direction 0 -1 0\n     length 4",
        "bone 'hip' is defined twice (first at line 16)",
    ),
    (
        (b"     name knee", b"     name :knee"),
        mt.FormatError,
        b"     name :knee",
        "bone name ':knee' cannot be written to ASF/AMC: it must be one word, not all digits, not starting with '#' or ':'",
    ),
    ((b"length 4", b"length four"), mt.NumberError, b"length four", "expected a number for length, found 'four'"),
    ((b"id 2", b"id 1e999"), mt.NumberError, b"id 1e999", "expected a whole number after id, found '1e999'"),
    (
        (b"direction 0 -1 0\n     length 5", b"direction 0 -1\n     length 5"),
        mt.CountError,
        b"direction 0 -1\n",
        "direction takes 3 numbers, found 2",
    ),
    (
        (b"dof rx ry", b"dof rx qq"),
        mt.FormatError,
        b"dof rx qq",
        "dof takes distinct channels of rx ry rz tx ty tz l, found 'rx qq'",
    ),
    ((b"            (-inf inf)\n", b""), mt.CountError, b"limits", "bone 'hip' has 2 dofs but 1 limits"),
    (
        (b"axis 0 0 0 XYZ\n     dof rx ry", b"axis 0 0 0 XYW\n     dof rx ry"),
        mt.FormatError,
        b"XYW",
        "expected an axis order such as XYZ, found 'XYW'",
    ),
    (
        (b"order TX", b"order QX"),
        mt.FormatError,
        b"order QX",
        "root order takes distinct channels of TX TY TZ RX RY RZ",
    ),
    (
        (b"    hip knee\n", b"    hip knee\n    knee hip\n"),
        mt.HierarchyError,
        b":hierarchy",
        "bone 'hip' has two parents, 'root' and 'knee'",
    ),
    (
        (b"    root hip\n", b"    root hip\n    foot toe\n"),
        mt.HierarchyError,
        b":hierarchy",
        "hierarchy names 'foot', which is not a bone",
    ),
]


@pytest.mark.parametrize(
    "change,error,where,words", ASF_CASES, ids=[c[1].__name__ + str(i) for i, c in enumerate(ASF_CASES)]
)
def test_bad_asf(tmp_path, change, error, where, words):
    bad = ASF.replace(*change, 1)
    assert bad != ASF
    path = write(tmp_path, "bad.asf", bad)
    with pytest.raises(error) as caught:
        mt.read_asf(path)
    assert str(caught.value).startswith(f"{path}, line {line_of(bad, where)}: {words}")


def test_unknown_sections_are_kept(tmp_path):
    asf = ASF + b":skin\n  skin.obj\n  scale 2\n"
    skeleton = mt.read_asf(write(tmp_path, "s.asf", asf))
    assert skeleton.sections == ((":skin", ("skin.obj", "scale 2")),)
    mt.write_asf(skeleton, tmp_path / "again.asf")
    assert mt.read_asf(tmp_path / "again.asf") == skeleton


def test_truncated_asf(tmp_path):
    for cut in (ASF.index(b"  end") - 3, ASF.index(b":hierarchy") - 1, len(ASF) - 6):
        path = write(tmp_path, "cut.asf", ASF[:cut])
        with pytest.raises((mt.TruncatedError, mt.MissingError), match=rf"^{re.escape(str(path))}, line \d+: "):
            mt.read_asf(path)


def test_frame_rate_from_header_argument_or_default(tmp_path):
    skeleton = mt.read_asf(write(tmp_path, "t.asf", ASF))
    assert mt.read_amc(write(tmp_path, "a.amc", AMC), skeleton).frame_rate == 120.0
    assert mt.read_amc(write(tmp_path, "a.amc", AMC), skeleton, frame_rate=60).frame_rate == 60.0
    with_rate = AMC.replace(b":DEGREES\n", b":DEGREES\n:SAMPLES-PER-SECOND 59.94\n")
    motion = mt.read_amc(write(tmp_path, "b.amc", with_rate), skeleton)
    assert motion.frame_rate == 59.94 and motion.first_frame == 1
    with pytest.raises(ValueError, match="the header says 59.94 frames per second, frame_rate=30"):
        mt.read_amc(write(tmp_path, "b.amc", with_rate), skeleton, frame_rate=30)
    resampled = motion.replace(frame_rate=30.0)
    mt.write_amc(resampled, tmp_path / "c.amc")
    assert mt.read_amc(tmp_path / "c.amc", skeleton).frame_rate == 30.0


def test_angle_unit_contradiction(tmp_path):
    skeleton = mt.read_asf(write(tmp_path, "t.asf", ASF))
    with pytest.raises(
        mt.FormatError, match=r"r.amc, line 4: the AMC says :RADIANS but its skeleton's angles are in deg"
    ):
        mt.read_amc(write(tmp_path, "r.amc", AMC.replace(b":DEGREES", b"\n\n:RADIANS")), skeleton)


def test_bad_rate_line(tmp_path):
    skeleton = mt.read_asf(write(tmp_path, "t.asf", ASF))
    with pytest.raises(
        mt.FormatError, match=r"q.amc, line 3: expected a number of frames per second after :SAMPLES-PER-SECOND"
    ):
        mt.read_amc(write(tmp_path, "q.amc", AMC.replace(b":DEGREES", b"\n:SAMPLES-PER-SECOND fast")), skeleton)


def test_failed_write_leaves_no_file(tmp_path, monkeypatch):
    skeleton = mt.read_asf(write(tmp_path, "t.asf", ASF))
    motion = mt.read_amc(write(tmp_path, "a.amc", AMC), skeleton).median(size=3)  # new values: formatted
    import motiontheater.formats.amc

    def broken(*args, **kwargs):
        raise OSError("disk full")

    monkeypatch.setattr(motiontheater.formats.amc, "format_frames", broken)
    with pytest.raises(OSError, match="disk full"):
        mt.write_amc(motion, tmp_path / "out.amc")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.amc", "t.asf"]
