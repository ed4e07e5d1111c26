"""The up axis of a take, from its frames: on every real BVH, on the same takes turned as z-up and
upside-down exporters write them, and where no legs are found by name."""

import numpy as np
import pytest

import motiontheater as mt
from corpus import ids, real_files
from motiontheater.feet.upright import take_forward, take_up
from variants import with_static_root

BVHS = real_files("*/*.bvh")
Z_UP = {"pybvh_bvh_example.bvh", "video2bvh_cxk.bvh", "zombie.bvh"}  # their producers' own frame


@pytest.mark.parametrize("path", BVHS, ids=ids(BVHS))
def test_every_real_bvh_stands_along_its_up_axis_turned_or_not(path):
    take = mt.read_bvh(path)
    found = take_up(take)
    assert found.axis == ("z" if path.name in Z_UP else "y"), found.reason
    if path.name == "sinusoidal.bvh":  # a synthetic chain: no legs to tell
        assert "no legs" in found.reason
        return
    assert "hips are above the ankles" in found.reason
    # turned by an exporter's static root (a quarter turn about x: y goes to z, z to -y)
    turned = take_up(with_static_root(take, turn=(90.0, 0.0, 0.0), keep_world=False)).axis
    assert turned == {"y": "z", "z": "-y"}[found.axis]
    upside_down = take_up(with_static_root(take, turn=(180.0, 0.0, 0.0), keep_world=False)).axis
    assert upside_down == "-" + found.axis


def test_acclaim_is_y_up_and_a_given_axis_wins(data_dir):
    take = mt.read_amc(data_dir / "cmu" / "01_01.amc", mt.read_asf(data_dir / "cmu" / "01.asf"))
    assert take_up(take).axis == "y"
    assert take_up(take, "+Z") == take_up(take, "z")
    assert take_up(take, "-x").axis == "-x" and take_up(take, "-x").reason == "given"
    with pytest.raises(ValueError, match="up must be an axis"):
        take_up(take, "up")


def test_a_take_without_frames_is_judged_by_its_rest_pose(data_dir):
    take = mt.read_bvh(data_dir / "bvh" / "walk01.bvh")
    empty = take.replace(values=np.empty((0, take.values.shape[1])))
    assert take_up(empty).axis == "y" and "no frames" in take_up(empty).reason


@pytest.mark.parametrize("axis", ["x", "y", "z", "-x", "-y", "-z"])
def test_the_turn_stands_the_up_axis_along_y(data_dir, axis):
    up = take_up(mt.read_bvh(data_dir / "bvh" / "walk01.bvh"), axis)
    np.testing.assert_array_equal(up.turn @ up.vector, [0.0, 1.0, 0.0])
    assert np.linalg.det(up.turn) == 1.0


def test_a_take_faces_the_way_it_travels_else_its_feet(data_dir):
    walk = mt.read_bvh(data_dir / "bvh" / "walk01.bvh")
    facing = take_forward(walk)
    assert facing.axis == "z" and "travels 5.54 m" in facing.reason
    assert take_forward(with_static_root(walk, turn=(90.0, 0.0, 0.0), keep_world=False)).axis == "-y"
    still = walk.replace(values=np.repeat(walk.values[:1], 30, axis=0))
    standing = take_forward(still)
    assert standing.axis == "z" and "feet point along it" in standing.reason
    assert take_forward(mt.read_bvh(data_dir / "bvh" / "sinusoidal.bvh")).axis is None
