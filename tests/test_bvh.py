"""BVH: every real file reads and writes back exactly; forward kinematics against bvh-toolbox and AMC."""

import csv
import io

import numpy as np
import pytest

import motiontheater as mt
from corpus import ids, real_files
from motiontheater.model.rates import rate_of_frame_time

BVHS = real_files("*/*.bvh")


@pytest.mark.parametrize("path", BVHS, ids=ids(BVHS))
def test_every_bvh_reads_and_writes_back_exactly(path):
    motion = mt.read_bvh(path)
    text = path.read_bytes()
    assert motion.frames == int(text.split(b"Frames:")[1].split()[0])
    assert len(motion.skeleton.channels) == sum(
        int(line.split()[1]) for line in text.splitlines() if line.strip().startswith(b"CHANNELS")
    )
    out = io.BytesIO()
    mt.write_bvh(motion, out)
    again = mt.read_bvh(io.BytesIO(out.getvalue()))
    assert again.skeleton == motion.skeleton
    assert again.values.tobytes() == motion.values.tobytes()
    assert again.frame_rate == motion.frame_rate and again.header == motion.header


def test_walk01_positions_equal_bvh_toolbox(data_dir):
    motion = mt.read_bvh(data_dir / "bvh" / "walk01.bvh")
    with open(data_dir / "bvh" / "walk01_pos.csv") as f:
        rows = list(csv.reader(f))
    header = [h.strip() for h in rows[0]]
    reference = np.array([[float(x) for x in row if x.strip()] for row in rows[1:]])
    positions = motion.positions()
    names = motion.skeleton.point_names
    assert "RightFoot_End" in names  # end sites are points, named as bvh-toolbox names them
    for j, name in enumerate(names):
        for a, axis in enumerate("xyz"):
            np.testing.assert_allclose(
                positions[:, j, a],
                reference[:, header.index(f"{name}.{axis}")],
                rtol=0,
                atol=1e-4,
                err_msg=f"{name}.{axis}",
            )


def test_the_same_take_as_amc_and_bvh(data_dir):
    """cmu/01_01: BVH frame k+1 (the first is an added T-pose) is AMC frame k; BVH joints sit where
    ASF bones start, so the BVH knee is the end of the femur."""
    amc = mt.read_amc(data_dir / "cmu" / "01_01.amc", mt.read_asf(data_dir / "cmu" / "01.asf"))
    bvh = mt.read_bvh(data_dir / "cmu" / "01_01.bvh")
    assert bvh.frames == amc.frames + 1
    pa, pb = amc.positions(), bvh.positions()
    pairs = {
        "Hips": "root",
        "LeftUpLeg": "lhipjoint",
        "LeftLeg": "lfemur",
        "LeftFoot": "ltibia",
        "LeftToeBase": "lfoot",
        "RightUpLeg": "rhipjoint",
        "RightLeg": "rfemur",
        "RightFoot": "rtibia",
        "RightToeBase": "rfoot",
    }
    for b, a in pairs.items():
        np.testing.assert_allclose(
            pb[1:, bvh.skeleton.point_names.index(b)],
            pa[:, amc.skeleton.joint_names.index(a)],
            rtol=0,
            atol=1e-3,
            err_msg=b,
        )


TINY = """HIERARCHY
ROOT hips bone
{
\tOFFSET 1 2 3
\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
\tJOINT arm.L:upper
\t{
\t\tOFFSET 0 5 0
\t\tCHANNELS 4 Xposition Zrotation Xrotation Yrotation
\t\tend site
\t\t{
\t\t\tOFFSET 0 4 0
\t\t}
\t}
}
MOTION
Frames: 2
Frame Time: 0.0083333
0 0 0 0 0 0 7 0 0 0
1 2 3 90 0 0 7 0 0 0
"""


def test_names_with_spaces_position_channels_and_end_sites():
    motion = mt.read_bvh(io.BytesIO(TINY.encode()))
    skeleton = motion.skeleton
    assert skeleton.root.name == "hips bone" and skeleton.bone_names == ("arm.L:upper", "arm.L:upper_End")
    assert skeleton.bone("arm.L:upper_End").end_site and motion.frame_rate == 120.0  # what 0.0083333 rounds
    p = motion.positions()
    # frame 1: the root's position channels replace its offset (0, 0, 0); the arm's Xposition 7 replaces offset x
    np.testing.assert_allclose(p[0], [[0, 0, 0], [7, 5, 0], [7, 9, 0]], atol=1e-12)
    # frame 2: root at (1, 2, 3) turned 90 degrees about z: the arm's (7, 5, 0) becomes (-5, 7, 0)
    np.testing.assert_allclose(p[1], [[1, 2, 3], [-4, 9, 3], [-8, 9, 3]], atol=1e-12)
    out = io.BytesIO()
    mt.write_bvh(motion, out)
    assert b"Frame Time: 0.0083333\n" in out.getvalue() and b"JOINT arm.L:upper" in out.getvalue()


@pytest.mark.parametrize(
    "change,error,line,words",
    [
        (("7 0 0 0\n1", "7 0 0\n1"), mt.CountError, 19, "a frame takes 10 values (the channels declared), found 9"),
        (("Frames: 2", "Frames: 3"), mt.TruncatedError, 21, "the header says 3 frames but the data holds 2"),
        (("Frames: 2", "Frames: 1"), mt.SequenceError, 20, "the header says 1 frames but the data holds more"),
        (
            ("Zrotation Xrotation Yrotation\n\tJOINT", "Zrotation Xrotation Wrotation\n\tJOINT"),
            mt.FormatError,
            5,
            "unknown or repeated channel 'Wrotation'",
        ),
        (("\t\t}\n\t}\n}", "\t\t}\n\t}"), mt.TruncatedError, 14, "joint 'hips bone' is not closed"),
        (("MOTION\n", "MOTON\n"), mt.MissingError, 21, "no MOTION section"),
        (
            ("JOINT arm.L:upper", "JOINT arm}upper"),
            mt.FormatError,
            6,
            "joint name 'arm}upper' cannot be written to BVH",
        ),
        (("1 2 3 90", "1 2 x 90"), mt.NumberError, 20, "expected a number as value 3 of the frame, found 'x'"),
        (
            ("Frame Time: 0.0083333", "Frame Time: inf"),
            mt.FormatError,
            18,
            "expected a positive, finite frame time in seconds, got 'inf'",
        ),
        (("Frame Time: 0.0083333", "Frame Time: 0"), mt.FormatError, 18, "expected a positive, finite frame time"),
        (("Frames: 2", "Frames: -2"), mt.FormatError, 17, "expected a whole number of frames, got '-2'"),
    ],
)
def test_bad_bvh(tmp_path, change, error, line, words):
    bad = TINY.replace(*change)
    assert bad != TINY
    path = tmp_path / "bad.bvh"
    path.write_text(bad)
    with pytest.raises(error) as caught:
        mt.read_bvh(path)
    assert str(caught.value).startswith(f"{path}, line {line}: {words}")


def test_missing_motion_section(tmp_path):
    path = tmp_path / "m.bvh"
    path.write_text(TINY.split("MOTION")[0])
    with pytest.raises(mt.MissingError, match=r"m.bvh, line \d+: no MOTION section"):
        mt.read_bvh(path)


def test_write_bvh_refuses_an_asf_motion(data_dir):
    motion = mt.read_amc(data_dir / "cmu" / "02_01.amc", mt.read_asf(data_dir / "cmu" / "02.asf"))
    with pytest.raises(ValueError, match="write_bvh needs a motion of a BVH skeleton"):
        mt.write_bvh(motion, io.BytesIO())


def test_any_run_of_blanks_and_tabs_parts_the_words():
    """bvhio's example.bvh has 'OFFSET\t 0.00\t 5.21' and 'CHANNELS\t 3'."""
    spaced = TINY.replace("OFFSET 0 5 0", "OFFSET\t 0 \t 5\t0").replace("CHANNELS 4 ", "CHANNELS \t 4\t ")
    spaced = spaced.replace("JOINT arm.L:upper", "JOINT\t \tarm.L:upper").replace("end site", "end \t site")
    assert spaced != TINY
    motion = mt.read_bvh(io.BytesIO(spaced.encode()))
    tiny = mt.read_bvh(io.BytesIO(TINY.encode()))
    assert motion.skeleton == tiny.skeleton and motion.values.tobytes() == tiny.values.tobytes()


@pytest.mark.parametrize(
    "text,rate",
    [
        ("0.0333333", 30.0),  # 7 digits: 30.00003 Hz taken literally
        ("0.033333", 30.0),
        (".0083333", 120.0),
        ("0.008333", 120.0),
        ("0.00833333", 120.0),
        ("0.016667", 60.0),
        ("0.041667", 24.0),
        ("0.0416667", 24.0),
        ("0.008", 125.0),  # 120 Hz rounds to it too, but 125 is what it says
        ("0.010000", 100.0),
        ("0.0333667", 30000 / 1001),  # NTSC video
        ("0.0104167", 96.0),
        ("0.03333333333333333", 30.0),  # full precision: the double that 1/30 is
        ("0.016666666666666666", 1 / 0.016666666666666666),
        ("0.0123", 81.0),  # a whole rate that rounds to it
        ("0.0123456", 1 / 0.0123456),  # none rounds to it: the literal rate
        ("8.3333e-3", 120.0),
    ],
)
def test_a_rounded_frame_time_is_the_rate_it_was_printed_from(text, rate):
    assert rate_of_frame_time(text) == rate
    motion = mt.read_bvh(io.BytesIO(TINY.replace("0.0083333", text).encode()))
    assert motion.frame_rate == rate
    out = io.BytesIO()
    mt.write_bvh(motion.median(size=3), out)  # a new motion: its Frame Time written as it was read
    assert f"Frame Time: {text}\n".encode() in out.getvalue()


def test_a_given_frame_rate_replaces_the_frame_time(tmp_path):
    path = tmp_path / "t.bvh"
    path.write_text(TINY)
    motion = mt.read_bvh(path, frame_rate=60)
    assert motion.frame_rate == 60.0 and mt.read_take(path, frame_rate=60).frame_rate == 60.0
    out = io.BytesIO()
    mt.write_bvh(motion, out)
    assert b"Frame Time: 0.016666666666666666\n" in out.getvalue()
    with pytest.raises(ValueError, match="the frame rate must be a positive number of frames per second, got 0"):
        mt.read_bvh(path, frame_rate=0)


def test_a_take_at_a_rounded_frame_time_resamples_to_its_own_rate(data_dir):
    take = mt.read_bvh(data_dir / "cmu" / "01_01.bvh")  # Frame Time: .0083333
    assert take.frame_rate == 120.0
    same = take.resample(rate=120)  # the ratio is 1 (it was 30000000000000000/15000015000014999)
    np.testing.assert_allclose(same.values, take.values, atol=1e-9)
    half = take.resample(rate=60)
    assert half.frame_rate == 60.0 and abs(half.frames - take.frames / 2) <= 1


def test_a_joint_named_as_the_root_is_refused_with_its_line(data_dir, tmp_path):
    text = (data_dir / "bvh" / "walk01.bvh").read_text()
    path = tmp_path / "twice.bvh"
    path.write_text(text.replace("JOINT RightUpLeg", "JOINT Hips", 1))
    with pytest.raises(mt.FormatError, match=r"twice.bvh, line 6: joint 'Hips' has the name of the ROOT \(line 2\)"):
        mt.read_bvh(path)
