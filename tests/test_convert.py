"""ASF/AMC <-> BVH conversions: forward kinematics gives the same points."""

import numpy as np
import pytest

import motiontheater as mt
from conftest import ids, real_files
from motiontheater.cli import main

BVHS = [p for p in real_files("*/*.bvh")]
AMCS = real_files("*/*.amc")


def asf_end_points_in_bvh(asf_motion, bvh_motion):
    """BVH point index of each ASF joint's end: the root, a child joint's start, or an End Site."""
    skeleton, names = asf_motion.skeleton, bvh_motion.skeleton.point_names
    index = []
    for joint in skeleton.joint_names:
        if joint == "root":
            index.append(0)
        else:
            children = skeleton.children(joint)
            index.append(names.index(children[0] if children else f"{joint}_End"))
    return index


@pytest.mark.parametrize("amc", AMCS, ids=ids(AMCS))
@pytest.mark.parametrize("order", ["ZXY", "XYZ"])
def test_amc_to_bvh_keeps_every_point(amc, order, tmp_path):
    motion = mt.read_amc(amc, mt.read_asf(mt.skeleton_path_for(amc)))
    bvh = mt.to_bvh(motion, order)
    mt.write_bvh(bvh, tmp_path / "c.bvh")
    again = mt.read_bvh(tmp_path / "c.bvh")
    expected = motion.positions()
    scale = np.abs(expected).max()
    np.testing.assert_allclose(
        again.positions()[:, asf_end_points_in_bvh(motion, again)], expected, rtol=0, atol=1e-6 * scale
    )


@pytest.mark.parametrize("bvh", BVHS, ids=ids(BVHS))
def test_bvh_to_amc_keeps_every_point(bvh, tmp_path):
    motion = mt.read_bvh(bvh)
    if any(set(b.dofs) & {"tx", "ty", "tz"} for b in motion.skeleton.bones):
        pytest.skip("position channels below the root")
    asf = mt.to_asf(motion)
    mt.write_asf(asf.skeleton, tmp_path / "c.asf")
    mt.write_amc(asf, tmp_path / "c.amc")
    again = mt.read_amc(tmp_path / "c.amc", mt.read_asf(tmp_path / "c.asf"))
    expected = motion.positions()
    names = again.skeleton.joint_names
    index = [0] + [names.index(n.replace(" ", "_")) for n in motion.skeleton.point_names[1:]]
    np.testing.assert_allclose(
        again.positions()[:, index], expected, rtol=0, atol=1e-6 * max(1.0, np.abs(expected).max())
    )


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
    assert main(["convert", str(tmp_path / "w.bvh"), str(tmp_path / "w.amc")]) == 0
    out = capsys.readouterr().out
    assert f"343 frames in {tmp_path / 'w.amc'} and its skeleton {tmp_path / 'w.asf'}" in out
    original = mt.read_amc(data_dir / "cmu" / "02_01.amc", mt.read_asf(data_dir / "cmu" / "02.asf"))
    back = mt.read_amc(tmp_path / "w.amc", mt.read_asf(tmp_path / "w.asf"))
    assert back.frames == 343
    # there and back: every ASF joint's end is at the same point
    bvh = mt.read_bvh(tmp_path / "w.bvh")
    names = back.skeleton.joint_names
    index = [0] + [names.index(n.replace(" ", "_")) for n in bvh.skeleton.point_names[1:]]
    expected = original.positions()
    np.testing.assert_allclose(
        back.positions()[:, index][:, asf_end_points_in_bvh(original, bvh)],
        expected,
        rtol=0,
        atol=1e-6 * np.abs(expected).max(),
    )
    assert main(["convert", str(tmp_path / "w.bvh"), str(tmp_path / "w.txt")]) == 2
    assert "w.txt: a take's file name must end in .amc or .bvh" in capsys.readouterr().err


def test_bad_order():
    with pytest.raises(ValueError, match="order must be one of XYZ"):
        mt.to_bvh(mt.Motion(mt.Skeleton(bones=(), hierarchy=()), np.zeros((1, 6))), "XXY")
