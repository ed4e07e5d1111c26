"""Length units: names and the Acclaim convention, a BVH's unit told from its size, and the unit of every
real character, checked against its height and against the same take in the other format."""

import io
import itertools

import numpy as np
import pytest

import motiontheater as mt
from corpus import ids, real_files
from motiontheater.model import units
from motiontheater.model.skeleton import settle_length_unit

BVHS = real_files("*/*.bvh")
ASFS = real_files("*/*.asf")
ADULTS = ("walk01.bvh", "test_freebvh.bvh", "test_mocapbank.bvh", "16_15.bvh")

# what each visible BVH is, and why (see units.size_up): unit, how chosen, up axis
EXPECTED = {
    "walk01.bvh": ("cm", "detected", "y"),  # 185 units tall
    "test_freebvh.bvh": ("cm", "detected", "y"),  # 178
    "test_mocapbank.bvh": ("cm", "detected", "y"),  # 167
    "16_15.bvh": ("cm", "detected", "y"),  # 177; and its root moves as 16_15.amc's times 5.644 (below)
    "jesse_dance.bvh": ("cm", "detected", "y"),  # a Rokoko rig drawn along x: sized from its poses, 154
    "AV_8Walk_Meredith_HVHA_Rep1.bvh": ("in", "detected", "y"),  # 60.5: 1.54 m, walking at 1.75 m/s
    "zombie.bvh": ("in", "detected", "z"),  # z-up, 45 tall; AnimatedDrawings scales it by 0.025 to metres
    "01_01.bvh": ("0.45", "detected", "y"),  # 25.6: CMU's conversion (LHipJoint, ...) keeps the ASF's inch/0.45
    "rest.bvh": ("0.45", "detected", "y"),  # 24, the same rig
    "sinusoidal.bvh": ("cm", "assumed", "y"),  # a synthetic 3-bone rig, 8 units
    # bvh-producers/ (SOURCES.md there says what each is)
    "AxisNeuronFakeServer_test.bvh": ("cm", "detected", "y"),  # Perception Neuron, 173
    "BvhToDeepMimic_0005_Walking001.bvh": ("in", "detected", "y"),  # SFU/NUS Vicon, 62: 1.58 m
    "MoDi_000000_joints_1_frames_64.bvh": ("m", "detected", "y"),  # SMPL names, 1.6
    "bvhTools_test2_lafan1.bvh": ("cm", "detected", "y"),  # LAFAN1: rest pose along x, sized from its poses
    "bvhTools_test3.bvh": ("m", "detected", "y"),  # a Blender export, 1.4
    "lafan1-resolved_Geno_bind.bvh": ("cm", "detected", "y"),  # 213 with the arms raised
    "makehuman_cmu_10_01.bvh": ("in", "detected", "y"),  # CMU subject 10 on a Character Studio rig, 64
    "pybvh_bvh_example.bvh": ("in", "detected", "z"),  # z-up, 64
    "pybvh_bvh_test1_2024-12.bvh": ("in", "detected", "y"),  # the same family y-up, 62
    "pybvh_bvh_test2.bvh": ("cm", "detected", "y"),  # Xsens MVN names, 182
    "pybvh_cmu_12_01_walk.bvh": ("0.45", "detected", "y"),  # 24: CMU's cgspeed conversion, as 01_01.bvh
    "video2bvh_cxk.bvh": ("mm", "detected", "z"),  # a video pose estimate, 1545
}


def standing_height(positions, axis):
    """Per frame, the extent of the points along the axis (file units or metres, as given)."""
    along = positions[..., "xyz".index(axis)]
    return along.max(axis=-1) - along.min(axis=-1)


@pytest.mark.parametrize(
    "text,meters",
    [
        ("m", 1.0),
        ("Metres", 1.0),
        ("cm", 0.01),
        ("centimeters", 0.01),
        ("mm", 0.001),
        ("in", 0.0254),
        ("inches", 0.0254),
        ("0.45", 0.0254 / 0.45),
        (" 1.0 ", 0.0254),
        ("0.0254", 1.0),
        ("2.54", 0.01),
    ],
)
def test_unit_text(text, meters):
    assert units.meters_per(text) == meters


@pytest.mark.parametrize("text", ["furlong", "", "0", "-0.45", "nan", "inf", "1 cm"])
def test_unknown_units_are_named(text):
    with pytest.raises(ValueError, match=f"unknown length unit '{text}': give m, cm, mm, in, or a number L"):
        units.meters_per(text)


@pytest.mark.parametrize(
    "text,label,named",
    [("cm", "cm", "cm"), ("0.45", "in/0.45", None), ("0.0254", "m", "m"), ("1.0", "in", "in"), (None, "in", "in")],
)
def test_unit_labels(text, label, named):
    assert units.label(text) == label and units.named(text) == named


def test_the_human_windows_of_the_units_do_not_overlap():
    """Each candidate unit claims the sizes that make a person of 1.0 to 2.54 m; no size is claimed
    twice, and from 39.37 to 254 units every size is claimed (inch below 100, cm from 100)."""
    low, high = units.HUMAN_HEIGHT
    windows = sorted((low / units.meters_per(u), high / units.meters_per(u), u) for u in units.DETECTABLE)
    for (_, end, _), (start, _, _) in itertools.pairwise(windows):
        assert end <= start * (1 + 1e-12)
    assert units.human_unit(39.37) is None and units.human_unit(39.38) == "in"
    assert units.human_unit(99.99) == "in" and units.human_unit(100) == "cm" and units.human_unit(253.9) == "cm"
    assert units.human_unit(254) is None and units.human_unit(999) is None and units.human_unit(1000) == "mm"
    assert units.human_unit(1.7) == "m" and units.human_unit(25.6) is None


def test_size_up_rules():
    t_pose = np.array([[0, 0, 0], [0, 170, 0], [-85, 140, 0], [85, 140, 0], [0, 0, 20]], float)
    sizing = units.size_up(t_pose)
    assert (sizing.unit, sizing.up, sizing.axis, sizing.height) == ("cm", "y", "y", 170.0)
    z_up = t_pose[:, [0, 2, 1]] / 2.54  # inches, standing along z
    sizing = units.size_up(z_up)
    assert (sizing.unit, sizing.up, sizing.axis) == ("in", "z", "z")
    lying = np.array([[0, 0, 0], [130, 20, 0], [60, -2, 6]], float)  # a rig drawn along x
    sizing = units.size_up(lying)
    assert (sizing.unit, sizing.up, sizing.axis, sizing.told_by) == ("cm", "y", "x", 130.0)
    tiny = units.size_up(t_pose / 10)
    assert tiny.unit is None and tiny.axis is None and tiny.told_by == tiny.height == 17.0
    with_nan = units.size_up(np.vstack([t_pose, [np.nan, 1e9, 0]]))
    assert with_nan.unit == "cm" and with_nan.height == 170.0
    assert units.size_up(np.empty((0, 3))).unit is None


@pytest.mark.parametrize("path", BVHS, ids=ids(BVHS))
def test_every_visible_bvh_has_the_unit_its_size_tells(path):
    skeleton = mt.read_bvh(path).skeleton
    unit, source, up = EXPECTED[path.name]
    assert (skeleton.length_unit, skeleton.length_source, skeleton.sizing().up) == (unit, source, up)
    assert skeleton.units == (("angle", "deg"),)  # a BVH file states no unit: nothing to write back


@pytest.mark.parametrize("name", ADULTS)
def test_adults_in_bvh_stand_1_2_to_2_2_m_tall(data_dir, name):
    motion = mt.read_bvh(next(data_dir.glob(f"*/{name}")))
    up = motion.skeleton.sizing().up
    heights = standing_height(motion.positions(meters=True), up)
    assert 1.2 <= heights[0] <= 2.2  # standing in the first frame
    assert 1.2 <= standing_height(motion.skeleton.rest_positions(), up) * motion.skeleton.meters_per_unit <= 2.2


@pytest.mark.parametrize("path", ASFS, ids=ids(ASFS))
def test_every_asf_character_stands_1_2_to_2_2_m_tall(path):
    skeleton = mt.read_asf(path)
    rest = skeleton.rest_positions() * skeleton.meters_per_unit
    assert 1.2 <= standing_height(rest, "y") <= 2.2
    take = sorted(path.parent.glob(path.stem.split("-")[0] + "_*.amc")) or sorted(path.parent.glob("*.amc"))
    motion = mt.read_amc(take[0], skeleton)
    assert 1.2 <= standing_height(motion.positions(meters=True)[0], "y") <= 2.2


def test_an_asf_stating_an_absurd_unit_is_read_in_the_one_that_fits(data_dir, tmp_path):
    """The edge file says 'length m' of numbers in millimetres (a 90.8 mm neck): its unit in effect
    is detected, and its text is written back as it was."""
    skeleton = mt.read_asf(data_dir / "edge" / "test.asf")
    assert (skeleton.unit("length"), skeleton.length_unit, skeleton.length_source) == ("m", "mm", "detected")
    mt.write_asf(skeleton, tmp_path / "t.asf")
    stated_line = next(line for line in (data_dir / "edge" / "test.asf").read_text().splitlines() if "length" in line)
    assert stated_line in (tmp_path / "t.asf").read_text().splitlines()
    stated = mt.read_asf(data_dir / "cmu" / "01.asf")
    assert (stated.length_unit, stated.length_source) == ("0.45", "stated")
    # a stated unit that makes a non-human but sane size stands: a 60 cm robot is no person in inches
    robot = stated.with_units(length_factor=60 / 27.72, length="cm")
    assert units.human_unit(robot.sizing().height) == "in"
    assert settle_length_unit(robot) is robot and robot.meters_per_unit == 0.01


def test_an_asf_without_length_is_in_inches(data_dir):
    text = (data_dir / "cmu" / "01.asf").read_text().replace("  length 0.45\n", "")
    skeleton = mt.read_asf(io.StringIO(text))
    assert skeleton.unit("length") is None and skeleton.length_source == "default"
    assert skeleton.meters_per_unit == 0.0254  # the Acclaim default: 0.45 times the CMU unit, so 0.69 m tall


def test_cmu_bvh_conversion_is_in_the_asf_unit(data_dir):
    """cmu/01_01.bvh is CMU's own BVH conversion: its numbers are the AMC's (frame k+1 = AMC frame k),
    in the ASF's unit, inch/0.45, which no size rule can tell (the character is 26 units tall): read
    it with unit="0.45".  cmu/16_15.bvh is another conversion, in centimetres, and detected."""
    amc = mt.read_amc(data_dir / "cmu" / "01_01.amc", mt.read_asf(data_dir / "cmu" / "01.asf"))
    bvh = mt.read_bvh(data_dir / "cmu" / "01_01.bvh", unit="0.45")
    assert bvh.skeleton.length_source == "given" and bvh.skeleton.meters_per_unit == amc.skeleton.meters_per_unit
    np.testing.assert_allclose(
        bvh.positions(meters=True)[1:, 0], amc.positions(meters=True)[:, 0], rtol=0, atol=1e-5
    )  # the root, to the BVH's 4 decimals
    amc16 = mt.read_amc(data_dir / "cmu" / "16_15.amc", mt.read_asf(data_dir / "cmu" / "16.asf"))
    bvh16 = mt.read_bvh(data_dir / "cmu" / "16_15.bvh")
    assert bvh16.skeleton.length_source == "detected"
    np.testing.assert_allclose(bvh16.positions(meters=True)[:, 0], amc16.positions(meters=True)[:, 0], atol=1e-4)


def test_a_given_unit_wins_and_stays(data_dir):
    walk = mt.read_bvh(data_dir / "bvh" / "walk01.bvh", unit="mm")
    assert (walk.skeleton.length_unit, walk.skeleton.length_source, walk.skeleton.meters_per_unit) == (
        "mm",
        "given",
        0.001,
    )
    assert walk.median(size=3).skeleton.length_choice == ("mm", "given")  # steps keep the skeleton's unit
    with pytest.raises(ValueError, match="unknown length unit 'parsec'"):
        mt.read_bvh(data_dir / "bvh" / "walk01.bvh", unit="parsec")
    amc = mt.read_take(data_dir / "cmu" / "02_01.amc", unit="cm")
    assert amc.skeleton.length_source == "given" and amc.skeleton.unit("length") == "0.45"  # the text stays


def test_to_meters_states_the_unit(data_dir):
    walk = mt.read_bvh(data_dir / "bvh" / "walk01.bvh")
    meters = walk.to_meters()
    assert meters.skeleton.length_choice is None and meters.skeleton.meters_per_unit == 1.0
    np.testing.assert_allclose(meters.positions(), walk.positions(meters=True), rtol=1e-14, atol=1e-15)


def test_the_rest_pose_of_a_bvh_with_position_channels_is_drawn_by_its_offsets():
    motion = mt.read_bvh(io.BytesIO(TINY_MOVING.encode()))
    rest = motion.skeleton.rest_positions()
    assert motion.skeleton.point_names == ("Hips", "Head", "Head_End", "Foot")
    np.testing.assert_array_equal(rest, [[0, 90, 0], [0, 170, 0], [0, 170, 0], [0, 0, 0]])
    assert motion.skeleton.length_unit == "cm"  # 170 tall: the channels, zero in motion, do not hide it


TINY_MOVING = """HIERARCHY
ROOT Hips
{
\tOFFSET 0 90 0
\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
\tJOINT Head
\t{
\t\tOFFSET 0 80 0
\t\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
\t\tEnd Site
\t\t{
\t\t\tOFFSET 0 0 0
\t\t}
\t}
\tJOINT Foot
\t{
\t\tOFFSET 0 -90 0
\t\tCHANNELS 3 Xposition Yposition Zposition
\t}
}
MOTION
Frames: 1
Frame Time: 0.01
0 0 0 0 0 0 0 0 0 0 0 0 0 0 0
"""


@pytest.mark.parametrize(
    "path", [p for p in BVHS if p.name != "sinusoidal.bvh"], ids=ids([p for p in BVHS if p.name != "sinusoidal.bvh"])
)
def test_every_real_figure_is_human_sized_in_metres(path):
    """The widest extent of frame 1, in metres by the detected unit: 0.9 to 2.4 m (the rig issue's
    bound; sinusoidal.bvh is a synthetic 3-bone rig of 8 units)."""
    pose = mt.read_bvh(path).positions(meters=True)[0]
    pose = pose[np.isfinite(pose).all(axis=1)]
    assert 0.9 <= np.ptp(pose, axis=0).max() <= 2.4
