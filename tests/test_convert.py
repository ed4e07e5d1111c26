"""ASF/AMC <-> BVH conversions: forward kinematics gives the same points, units go with the motion."""

import io
from dataclasses import replace

import numpy as np
import pytest

import motiontheater as mt
from corpus import ids, real_files
from motiontheater.cli import main
from motiontheater.editing.convert import _notes

BVHS = real_files("*/*.bvh")
AMCS = real_files("*/*.amc")
# one take of each source (CMU, HDM05, the non-CMU edge file) goes through files both ways
FILE_TRIPS = [p for p in AMCS if p.name in ("02_01.amc", "HDM_bd_hopBothLegs1hops_005_120.amc", "test.amc")]
TRANSLATIONS = ("tx", "ty", "tz")


def asf_end_points_in_bvh(asf_skeleton, bvh_skeleton):
    """BVH point index of each ASF joint's end: the root, a child joint's start, or ``<bone>_End`` (an
    End Site, or the joint of position channels that ends a bone with translation dofs); a bone that
    to_asf made to reach a joint ends at that joint."""
    names, index = bvh_skeleton.point_names, []
    _, connectors, _ = _notes(asf_skeleton)
    for joint in asf_skeleton.joint_names:
        if joint == "root":
            index.append(0)
        elif joint in connectors:
            index.append(names.index(joint.split("_to_", 1)[1]))
        else:
            children = [c for c in asf_skeleton.children(joint) if c not in connectors]
            end = children[0] if children else f"{joint}_End"
            index.append(names.index(end if end in names else joint))  # a BVH leaf joint is its own end
    return index


def bvh_points_in_asf(bvh_skeleton, asf_skeleton):
    """ASF point index of each BVH point, as to_asf lays them: a joint is where the bone named after
    its parent ends (the root's children: the root), or where the bone made to reach it ends."""
    names = asf_skeleton.joint_names
    index = [0]
    for point in bvh_skeleton.point_names[1:]:
        parent = bvh_skeleton.parent(point)
        start = bvh_skeleton.root.name if parent == "root" else parent
        reach = f"{start}_to_{point}".replace(" ", "_")
        index.append(
            names.index(reach) if reach in names else 0 if parent == "root" else names.index(parent.replace(" ", "_"))
        )
    return index


def assert_same_points(actual, expected):
    """Positions equal within 1e-9 of the motion's scale (its largest coordinate), NaN where NaN."""
    scale = max(1.0, float(np.nanmax(np.abs(expected)))) if expected.size else 1.0
    np.testing.assert_allclose(actual, expected, rtol=0, atol=1e-9 * scale)


def amc_through_files(motion, folder, name="c"):
    mt.write_asf(motion.skeleton, folder / f"{name}.asf")
    mt.write_amc(motion, folder / f"{name}.amc")
    return mt.read_amc(folder / f"{name}.amc", mt.read_asf(folder / f"{name}.asf"))


def bvh_through_file(motion, folder, name="c", unit=None):
    mt.write_bvh(motion, folder / f"{name}.bvh")
    return mt.read_bvh(folder / f"{name}.bvh", unit=unit)


def read_take(amc):
    return mt.read_amc(amc, mt.read_asf(mt.skeleton_path_for(amc)))


def every_joint_moves(motion, seed=0):
    """A BVH variant with position channels on every joint, as Bandai Namco's dataset has them: the
    offset itself, drifting a little, so that the channels matter."""
    skeleton, rng = motion.skeleton, np.random.default_rng(seed)
    bones = tuple(
        b if b.end_site else replace(b, dofs=TRANSLATIONS + tuple(d for d in b.dofs if d not in TRANSLATIONS))
        for b in skeleton.bones
    )
    root_turns = tuple(d for d in skeleton.root.order if d not in TRANSLATIONS)
    moving = replace(skeleton, bones=bones, root=replace(skeleton.root, order=TRANSLATIONS + root_turns))
    columns = []
    for joint, dof in moving.channels:
        if dof in TRANSLATIONS and not moving.is_root(joint):
            offset = skeleton.bone(joint).direction[TRANSLATIONS.index(dof)]
            columns.append(offset + 0.02 * offset * np.sin(np.arange(motion.frames) / 5 + rng.uniform(0, 6)))
        else:
            columns.append(motion.channel(joint, dof))
    return mt.Motion(moving, np.column_stack(columns), frame_rate=motion.frame_rate)


def stretching_bones(motion, seed=0):
    """An ASF/AMC variant whose bones translate (tx ty tz) and stretch (l): a root child, a bone with a
    turned axis, a middle bone and leaves."""
    extra = {"lfemur": ("tx", "l"), "head": ("ty", "tz"), "rhumerus": ("l", "tx", "ty", "tz"), "ltoes": ("l",)}
    extra["lowerback"] = ("tz",)
    skeleton, rng = motion.skeleton, np.random.default_rng(seed)
    bones = tuple(replace(b, dofs=b.dofs + extra.get(b.name, ()), limits=()) for b in skeleton.bones)
    moving = replace(skeleton, bones=bones)
    columns = []
    for joint, dof in moving.channels:
        if joint != "root" and dof in (*TRANSLATIONS, "l"):
            columns.append(rng.uniform(-1, 1) + 0.5 * np.sin(np.arange(motion.frames) / 9 + rng.uniform(0, 6)))
        else:
            columns.append(motion.channel(joint, dof))
    return mt.Motion(moving, np.column_stack(columns), frame_rate=motion.frame_rate)


@pytest.mark.parametrize("amc", AMCS, ids=ids(AMCS))
@pytest.mark.parametrize("order", ["ZXY", "XYZ"])
def test_amc_to_bvh_and_back_keeps_every_point_and_the_unit(amc, order):
    motion = read_take(amc)
    bvh = mt.to_bvh(motion, order)
    expected = motion.positions()
    assert_same_points(bvh.positions()[:, asf_end_points_in_bvh(motion.skeleton, bvh.skeleton)], expected)
    back = mt.to_asf(bvh)
    assert back.skeleton.units == motion.skeleton.units  # :units length 0.45 (or the edge file's "m") kept
    assert bvh.skeleton.meters_per_unit == back.skeleton.meters_per_unit == motion.skeleton.meters_per_unit
    points = bvh_points_in_asf(bvh.skeleton, back.skeleton)
    assert_same_points(back.positions()[:, points][:, asf_end_points_in_bvh(motion.skeleton, bvh.skeleton)], expected)


@pytest.mark.parametrize("amc", FILE_TRIPS, ids=ids(FILE_TRIPS))
def test_amc_to_bvh_to_amc_through_files(amc, tmp_path):
    """Through files the BVH needs its unit given (a BVH file states none); the AMC written at the
    end says :units length as the first did, and every point is where it was, in metres too."""
    motion = read_take(amc)
    motion = motion.crop(motion.first_frame, min(motion.last_frame, motion.first_frame + 199))
    unit = motion.skeleton.length_unit
    bvh = bvh_through_file(mt.to_bvh(motion), tmp_path, unit=unit)
    back = amc_through_files(mt.to_asf(bvh), tmp_path)
    assert back.skeleton.unit("length") == unit
    assert back.skeleton.meters_per_unit == motion.skeleton.meters_per_unit
    points = bvh_points_in_asf(bvh.skeleton, back.skeleton)
    ends = asf_end_points_in_bvh(motion.skeleton, bvh.skeleton)
    assert_same_points(back.positions()[:, points][:, ends], motion.positions())
    assert_same_points(back.positions(meters=True)[:, points][:, ends], motion.positions(meters=True))


@pytest.mark.parametrize("bvh", BVHS, ids=ids(BVHS))
@pytest.mark.parametrize("variant", ["as found", "every joint moves"])
def test_every_bvh_to_amc_and_back_through_files(bvh, variant, tmp_path):
    motion = mt.read_bvh(bvh)
    if variant == "every joint moves":
        motion = bvh_through_file(every_joint_moves(motion.crop(1, min(motion.frames, 60))), tmp_path, "moving")
        assert motion.skeleton.length_unit == mt.read_bvh(bvh).skeleton.length_unit  # the same size: the same unit
    expected = motion.positions()
    asf = amc_through_files(mt.to_asf(motion), tmp_path)
    assert asf.skeleton.unit("length") == motion.skeleton.length_unit  # detected or assumed, now stated
    points = bvh_points_in_asf(motion.skeleton, asf.skeleton)
    assert_same_points(asf.positions()[:, points], expected)
    assert_same_points(asf.positions(meters=True)[:, points], motion.positions(meters=True))
    again = bvh_through_file(mt.to_bvh(asf), tmp_path, unit=asf.skeleton.length_unit)
    assert_same_points(again.positions()[:, asf_end_points_in_bvh(asf.skeleton, again.skeleton)][:, points], expected)


def test_bones_that_translate_and_stretch_convert_both_ways(data_dir, tmp_path):
    motion = amc_through_files(stretching_bones(read_take(data_dir / "cmu" / "02_01.amc").crop(1, 120)), tmp_path)
    assert motion.skeleton.bone("rhumerus").dofs == ("rx", "ry", "rz", "l", "tx", "ty", "tz")
    bvh = bvh_through_file(mt.to_bvh(motion), tmp_path, unit="0.45")
    # the leaf bone 'head' moves its end: a joint of position channels ends it, an End Site ends that
    assert bvh.skeleton.dofs("head_End") == TRANSLATIONS and bvh.skeleton.bone("head_End_End").end_site
    # the joint at the end of rhumerus (which translates) carries position channels; its twin does not
    assert bvh.skeleton.dofs("rradius")[:3] == TRANSLATIONS and bvh.skeleton.dofs("lradius")[:3] != TRANSLATIONS
    ends = asf_end_points_in_bvh(motion.skeleton, bvh.skeleton)
    expected = motion.positions()
    assert_same_points(bvh.positions()[:, ends], expected)
    back = amc_through_files(mt.to_asf(bvh), tmp_path, "back")
    assert_same_points(back.positions()[:, bvh_points_in_asf(bvh.skeleton, back.skeleton)][:, ends], expected)


def test_position_channels_become_the_change_from_the_offset(data_dir):
    """Where a BVH repeats its offsets in its position channels (Bandai Namco's files), the ASF's
    translation dofs are zero and its rest pose is the BVH's."""
    walk = mt.read_bvh(data_dir / "bvh" / "walk01.bvh").crop(1, 10)
    moving = every_joint_moves(walk)
    still = moving.replace(
        values=np.column_stack(
            [
                np.full(walk.frames, moving.skeleton.bone(j).direction[TRANSLATIONS.index(d)])
                if d in TRANSLATIONS and not moving.skeleton.is_root(j)
                else moving.channel(j, d)
                for j, d in moving.skeleton.channels
            ]
        )
    )
    asf = mt.to_asf(still)
    shifts = [c for c, (j, d) in enumerate(asf.skeleton.channels) if j != "root" and d in TRANSLATIONS]
    assert shifts and not asf.values[:, shifts].any()
    rest = asf.skeleton.rest_positions()[bvh_points_in_asf(walk.skeleton, asf.skeleton)]
    bvh_rest = walk.skeleton.rest_positions()
    np.testing.assert_allclose(rest - rest[0], bvh_rest - bvh_rest[0], rtol=0, atol=1e-12)  # up to the root's place
    assert_same_points(asf.positions()[:, bvh_points_in_asf(walk.skeleton, asf.skeleton)], walk.positions())


def test_a_bvh_unit_goes_into_the_asf(data_dir):
    zombie = mt.read_bvh(data_dir / "bvh" / "zombie.bvh")
    asf = mt.to_asf(zombie)
    assert asf.skeleton.units == (("mass", "1.0"), ("length", "in"), ("angle", "deg"))
    assert asf.skeleton.length_source == "detected"  # until written: a written ASF states it
    given = mt.to_asf(mt.read_bvh(data_dir / "bvh" / "zombie.bvh", unit="0.45"))
    assert given.skeleton.unit("length") == "0.45" and given.skeleton.meters_per_unit == 0.0254 / 0.45


def test_convert_command(data_dir, tmp_path, capsys):
    assert (
        main(
            [
                "convert",
                str(data_dir / "cmu" / "02_01.amc"),
                str(tmp_path / "w.bvh"),
                "--asf",
                str(data_dir / "cmu" / "02.asf"),
            ]
        )
        == 0
    )
    captured = capsys.readouterr()
    # a CMU character is 27 units tall, named as CMU names it: read back as a BVH, its unit is told again
    assert "--unit" not in captured.err
    assert mt.read_bvh(tmp_path / "w.bvh").skeleton.length_choice == ("0.45", "detected")
    assert main(["convert", str(tmp_path / "w.bvh"), str(tmp_path / "w.amc")]) == 0
    out = capsys.readouterr().out
    assert f"343 frames in {tmp_path / 'w.amc'} and its skeleton {tmp_path / 'w.asf'}" in out
    original = mt.read_amc(data_dir / "cmu" / "02_01.amc", mt.read_asf(data_dir / "cmu" / "02.asf"))
    back = mt.read_amc(tmp_path / "w.amc", mt.read_asf(tmp_path / "w.asf"))
    assert back.frames == 343
    assert "  length 0.45\n" in (tmp_path / "w.asf").read_text()
    # there and back: every ASF joint's end is at the same point
    bvh = mt.read_bvh(tmp_path / "w.bvh")
    expected = original.positions()
    ends = asf_end_points_in_bvh(original.skeleton, bvh.skeleton)
    assert_same_points(back.positions()[:, bvh_points_in_asf(bvh.skeleton, back.skeleton)][:, ends], expected)
    assert main(["convert", str(tmp_path / "w.bvh"), str(tmp_path / "w.txt")]) == 2
    assert "w.txt: a take's file name must end in .amc, .bvh, .glb or .gltf" in capsys.readouterr().err


def test_convert_command_says_when_a_unit_was_assumed(data_dir, tmp_path, capsys):
    assert main(["convert", str(data_dir / "bvh" / "sinusoidal.bvh"), "-o", str(tmp_path / "s.amc")]) == 0
    err = capsys.readouterr().err
    assert "the length unit of the input was assumed (cm)" in err and "--unit UNIT" in err
    assert main(["convert", str(data_dir / "bvh" / "walk01.bvh"), "-o", str(tmp_path / "w.amc")]) == 0
    assert capsys.readouterr().err == ""  # detected, and nothing to say
    assert main(["median", str(data_dir / "bvh" / "sinusoidal.bvh"), "--size", "3", "-o", str(tmp_path / "s.bvh")]) == 0
    assert capsys.readouterr().err == ""  # a BVH in, a BVH out: its unit, assumed again, matters to neither


def test_bad_order():
    with pytest.raises(ValueError, match="order must be one of XYZ"):
        mt.to_bvh(mt.Motion(mt.Skeleton(bones=(), hierarchy=()), np.zeros((1, 6))), "XXY")


def test_a_bone_without_dofs_is_a_joint_of_rotations_held_at_zero(data_dir):
    """pybvh, bvhsdk and bvh-toolbox's exporter refuse or crash on CHANNELS 0 (CMU's lhipjoint)."""
    bvh = mt.to_bvh(read_take(data_dir / "cmu" / "02_01.amc"))
    assert bvh.skeleton.dofs("lhipjoint") == ("rz", "rx", "ry")
    assert not bvh.values[:, bvh.columns("lhipjoint")].any()
    out = io.BytesIO()
    mt.write_bvh(bvh, out)
    assert b"CHANNELS 0" not in out.getvalue()
    assert all(not b.dofs for b in bvh.skeleton.bones if b.end_site)


def by_name(motion):
    points = motion.positions()
    return {name: points[:, i] for i, name in enumerate(motion.skeleton.point_names)}


def tree_of(skeleton):
    return {name: skeleton.parent(name) for name in skeleton.bone_names}


@pytest.mark.parametrize("bvh", BVHS, ids=ids(BVHS))
def test_bvh_to_asf_to_bvh_gives_the_same_joints_names_and_points(bvh, tmp_path):
    """No joint renamed one down the chain, no `_End_End`, the root keeps its name (Hips)."""
    motion = mt.read_bvh(bvh)
    motion = motion.crop(1, min(motion.frames, 120))
    asf = amc_through_files(mt.to_asf(motion), tmp_path)
    again = bvh_through_file(mt.to_bvh(asf), tmp_path, unit=asf.skeleton.length_unit)
    assert again.skeleton.root.name == motion.skeleton.root.name
    assert sorted(again.skeleton.point_names) == sorted(motion.skeleton.point_names)
    assert tree_of(again.skeleton) == tree_of(motion.skeleton)
    assert {b.name for b in again.skeleton.bones if b.end_site} == {b.name for b in motion.skeleton.bones if b.end_site}
    expected, got = by_name(motion), by_name(again)
    for name, points in expected.items():
        assert_same_points(got[name], points)


@pytest.mark.parametrize("amc", AMCS, ids=ids(AMCS))
def test_amc_to_bvh_to_amc_gives_the_same_bones_and_points(amc, tmp_path):
    motion = read_take(amc)
    motion = motion.crop(motion.first_frame, min(motion.last_frame, motion.first_frame + 119))
    bvh = bvh_through_file(mt.to_bvh(motion), tmp_path, unit=motion.skeleton.length_unit)
    back = amc_through_files(mt.to_asf(bvh), tmp_path)
    assert sorted(back.skeleton.bone_names) == sorted(motion.skeleton.bone_names)
    assert tree_of(back.skeleton) == tree_of(motion.skeleton)
    expected, got = by_name(motion), by_name(back)
    for name, points in expected.items():
        assert_same_points(got[name], points)
