"""Every ASF/AMC of the real corpus: read, checked against the file text, written back exactly."""

import io
import re

import numpy as np
import pytest

import motiontheater as mt
from corpus import ids, real_files
from motiontheater._io import PLAIN
from twins.text import parse_amc

ASFS = real_files("*/*.asf")
AMCS = real_files("*/*.amc")
REFS = real_files("hdm05/*.ref.npz")


def load(amc):
    return mt.read_amc(amc, mt.read_asf(mt.skeleton_path_for(amc)))


@pytest.mark.parametrize("asf", ASFS, ids=ids(ASFS))
def test_every_asf_reads_and_writes_back_identically(asf, tmp_path):
    skeleton = mt.read_asf(asf)
    text = asf.read_bytes()
    assert len(skeleton.bones) == text.count(b"begin") - 1  # one begin is the hierarchy's
    assert skeleton.bone_names == tuple(
        re.findall(rb"^\s*name\s+(\S+)", text, re.MULTILINE)[i].decode() for i in range(len(skeleton.bones))
    )
    mt.write_asf(skeleton, tmp_path / "out.asf")
    assert mt.read_asf(tmp_path / "out.asf") == skeleton


@pytest.mark.parametrize("amc", AMCS, ids=ids(AMCS))
def test_every_amc_equals_a_python_reading_of_its_text(amc):
    motion = load(amc)
    values, first = parse_amc(amc.read_bytes(), motion.skeleton)
    assert motion.frames == len(values) == len(re.findall(rb"^\s*\d+\s*$", amc.read_bytes(), re.MULTILINE))
    assert motion.first_frame == first
    np.testing.assert_array_equal(motion.values, values)
    assert motion.frame_rate == 120.0
    assert not motion.values.flags.writeable


@pytest.mark.parametrize("amc", AMCS, ids=ids(AMCS))
def test_every_amc_writes_back_bit_identically(amc, tmp_path):
    motion = load(amc)
    mt.write_amc(motion, tmp_path / "out.amc")
    again = mt.read_amc(tmp_path / "out.amc", motion.skeleton)
    assert again.values.tobytes() == motion.values.tobytes()  # bit-identical, -0.0 and NaN included
    assert (again.first_frame, again.frame_rate, again.header, again.line_order) == (
        motion.first_frame,
        motion.frame_rate,
        motion.header,
        motion.line_order,
    )
    # Numbers keep their short form: the file does not grow.
    assert (tmp_path / "out.amc").stat().st_size <= amc.stat().st_size * 1.02


@pytest.mark.parametrize("ref", REFS, ids=ids(REFS))
def test_hdm05_root_translation_is_amc_root_over_length_unit(ref):
    expected = np.load(ref)["root_translation"]
    motion = load(ref.with_name(ref.name.replace(".ref.npz", ".amc")))
    root = motion.values[:, motion.columns("root", ("tx", "ty", "tz"))]
    np.testing.assert_allclose(root / 0.45, expected, rtol=1e-15, atol=0)


def test_number_text_is_kept_short_and_in_the_files_style(data_dir):
    """A value read as 3.64024e-015 is written in the shortest form, not with 17 digits, with the
    file's exponent digits and line endings, or in the plain style when asked."""
    amc = data_dir / "cmu" / "01_01.amc"
    motion = load(amc)
    assert b"rclavicle 3.64024e-015 -6.75868e-015\r\n" in amc.read_bytes()
    out = io.BytesIO()
    mt.write_amc(motion, out)  # a file object: written through the formatter, not copied
    assert b"rclavicle 3.64024e-015 -6.75868e-015\r\n" in out.getvalue()
    plain = io.BytesIO()
    mt.write_amc(motion.replace(style=PLAIN), plain)
    assert b"rclavicle 3.64024e-15 -6.75868e-15\n" in plain.getvalue()


def test_latin1_header_survives_a_round_trip(data_dir, tmp_path):
    amc = data_dir / "hdm05" / "HDM_bd_squat1Reps_003_120.amc"
    motion = load(amc)
    assert "Bonn" in motion.header[0]
    mt.write_amc(motion.replace(values=motion.values.copy()), tmp_path / "out.amc")  # through the formatter
    first_line = (tmp_path / "out.amc").read_bytes().split(b"\r\n")[0]
    assert first_line == amc.read_bytes().split(b"\r\n")[0]  # the latin-1 byte unchanged


def test_edge_file_skeleton(data_dir):
    """A non-CMU file: tabs, 'length m', non-unit directions, hierarchy out of order."""
    skeleton = mt.read_asf(data_dir / "edge" / "test.asf")
    # it says metres, but its numbers are millimetres (a 1.58 m person, not a 1582 m one): the
    # stated text stays, for writing back, and the unit in effect is the detected one
    assert skeleton.unit("length") == "m"
    assert skeleton.length_unit == "mm" and skeleton.length_source == "detected"
    assert skeleton.meters_per_unit == 0.001
    assert skeleton.unit("mass") == "kg"
    assert skeleton.documentation == ("fps:30",)
    head = skeleton.bone("Head")
    assert head.direction == (-18.5, 116.2, -38.8) and head.length == 123.9
    assert head.limits == ((-np.inf, np.inf),) * 3
    motion = mt.read_amc(data_dir / "edge" / "test.amc", skeleton)
    assert motion.line_order[:5] == ("Head", "Neck", "LeftCollar", "Torso", "root")
    np.testing.assert_array_equal(motion.values[0, motion.columns("root")], [141.43, 25.31, 2764.41, -0.82, 7.02, 0.59])


def test_cmu_skeleton_in_detail(data_dir):
    s = mt.read_asf(data_dir / "cmu" / "01.asf")
    assert s.name == "VICON" and s.version == "1.10"
    assert s.units == (("mass", "1.0"), ("length", "0.45"), ("angle", "deg"))
    assert s.root == mt.Root()
    femur = s.bone("lfemur")
    assert femur.id == 2 and femur.axis == (0.0, 0.0, 20.0) and femur.axis_order == "XYZ"
    assert femur.dofs == ("rx", "ry", "rz") and femur.limits == ((-160.0, 20.0), (-70.0, 70.0), (-60.0, 70.0))
    assert s.parent("lfemur") == "lhipjoint" and s.children("thorax") == ("lowerneck", "lclavicle", "rclavicle")
    assert s.bone("lfoot").axis == (-90.0, 7.62852e-16, 20.0)
    assert len(s.channels) == 62 and s.channels[:7] == (
        ("root", "tx"),
        ("root", "ty"),
        ("root", "tz"),
        ("root", "rx"),
        ("root", "ry"),
        ("root", "rz"),
        ("lfemur", "rx"),
    )


def test_to_meters_follows_the_acclaim_convention(data_dir):
    motion = load(data_dir / "cmu" / "01_01.amc")
    meters = motion.to_meters()
    factor = 0.0254 / 0.45
    np.testing.assert_allclose(meters.channel("root", "ty"), motion.channel("root", "ty") * factor, rtol=1e-15)
    np.testing.assert_array_equal(meters.channel("lfemur", "rx"), motion.channel("lfemur", "rx"))
    assert meters.skeleton.bone("lfemur").length == pytest.approx(7.1578 * factor, rel=1e-15)
    assert meters.skeleton.meters_per_unit == 1.0
    assert motion.channel("root", "ty")[0] == 17.8693  # the input is untouched
