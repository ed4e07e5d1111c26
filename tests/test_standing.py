"""A rig whose rest pose does not stand, re-rested on a standing frame: the twin draws every pose
exactly as the rig does, and its channels convert both ways."""

import numpy as np
import pytest

import motiontheater as mt
from corpus import ids, real_files
from motiontheater.characters.standing import rested
from motiontheater.model.rig import STANDING, standing_height

LYING = [p for p in real_files("*/*.bvh") if p.name in ("bvhTools_test2_lafan1.bvh", "jesse_dance.bvh")]


@pytest.mark.parametrize("path", LYING, ids=ids(LYING))
def test_the_twin_stands_and_draws_the_same_motion(path):
    take = mt.read_bvh(path)
    skeleton = take.skeleton
    assert standing_height(skeleton.rest_positions()) <= STANDING  # why it is here
    assert skeleton.standing is not None
    twin = rested(skeleton, np.array(skeleton.standing))
    assert twin is not None and standing_height(twin.skeleton.rest_positions()) > STANDING
    moved = twin.into(take.values)
    size = float(np.ptp(take.positions()[0], axis=0).max())
    drawn = mt.Motion(twin.skeleton, moved, frame_rate=take.frame_rate).positions()
    np.testing.assert_allclose(drawn, take.positions(), rtol=0, atol=1e-9 * size)
    np.testing.assert_allclose(
        mt.Motion(skeleton, twin.back(moved)).positions(), take.positions(), rtol=0, atol=1e-9 * size
    )
    # the standing frame is the twin's rest pose
    frame = int(np.flatnonzero((take.values == np.array(skeleton.standing)).all(axis=1))[0])
    rest = twin.skeleton.rest_positions() + (take.positions()[frame, 0] - twin.skeleton.rest_positions()[0])
    np.testing.assert_allclose(rest, take.positions()[frame], rtol=0, atol=1e-9 * size)


def test_a_rig_that_stands_at_rest_keeps_no_standing_frame(data_dir):
    assert mt.read_bvh(data_dir / "bvh" / "walk01.bvh").skeleton.standing is None


def test_a_joint_with_fewer_than_three_rotations_has_no_twin(data_dir):
    cmu = mt.read_bvh(data_dir / "cmu" / "01_01.bvh").skeleton
    partial = mt.read_asf(data_dir / "cmu" / "01.asf")  # knees turn about one axis
    assert rested(partial, np.zeros(len(partial.channels))) is None
    assert rested(cmu, np.zeros(len(cmu.channels))) is not None
