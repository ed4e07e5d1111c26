"""The BVH motiontheater writes, read by Blender's BVH importer: every joint of every real take
(an ASF/AMC take through its conversion) where motiontheater's forward kinematics puts it, at
every frame, within 0.01 mm; and z-up and game-rig variants of real BVH likewise.  Blender keys
frame i at scene frame 1 + i and rounds the scene's rate (30 Hz for a Frame Time of 0.033333), so
it is sampled at its keys, counted at the take's rate."""

import numpy as np
import pytest

import motiontheater as mt
from consumers import blender_positions, needs_blender
from corpus import real_files
from variants import with_offset_channels, with_static_root

pytestmark = needs_blender

TOLERANCE = 1e-5  # metres: 0.01 mm
TAKES = real_files("*/*.amc") + real_files("*/*.bvh")
VARIANTS = {
    "game rig": lambda take: with_static_root(with_offset_channels(take), shift=(250.0, 0.0, -400.0)),
    "z-up": lambda take: with_static_root(take, turn=(90.0, 0.0, 0.0), keep_world=False),
}
VARIANT_TAKES = [p for p in TAKES if p.name in ("walk01.bvh", "BvhToDeepMimic_0005_Walking001.bvh")]
CASES = [(p, None) for p in TAKES] + [(p, v) for p in VARIANT_TAKES for v in VARIANTS]
IDS = [f"{p.parent.name}/{p.name}" + (f"-{v}" if v else "") for p, v in CASES]


def bvh_of(path, variant):
    take = mt.read_take(path)
    take = take if take.skeleton.convention == "bvh" else mt.to_bvh(take)
    return take if variant is None else VARIANTS[variant](take)


@pytest.fixture(scope="module")
def found(tmp_path_factory):
    """Each case's BVH take, and the joint positions Blender reads from the file we write of it."""
    folder = tmp_path_factory.mktemp("bvh")
    takes, jobs = {}, []
    for (path, variant), name in zip(CASES, IDS):
        take = bvh_of(path, variant)
        target = folder / (name.replace("/", "_").replace(" ", "_") + ".bvh")
        mt.write_bvh(take, target)
        takes[name] = take
        jobs.append((target, np.arange(take.frames) / take.frame_rate, take.frame_rate))
    positions = blender_positions(jobs, tmp_path_factory.mktemp("blender"))
    return {name: (takes[name], got) for name, got in zip(IDS, positions)}


@pytest.mark.parametrize("case", IDS)
def test_blender_puts_every_joint_where_we_do(found, case):
    take, got = found[case]
    skeleton = take.skeleton
    # Blender makes a bone of each joint; an End Site is a bone's tail, not a bone
    index = [i for i, n in enumerate(skeleton.joint_names) if i == 0 or not skeleton.bone(n).end_site]
    joints = [skeleton.point_names[i] for i in index]
    assert sorted(got) == sorted(joints)
    points = take.positions()[:, index]
    drawn = np.stack([got[j] for j in joints], axis=1)
    np.testing.assert_allclose(drawn, points, rtol=0, atol=TOLERANCE / take.skeleton.meters_per_unit)
