"""Speed of retargeting against its vectorised numpy twin, in one run.

Run: python -m pytest benchmarks/bench_retarget.py
The take is cmu/01_01 (2751 frames, 31 joints) put on walk01's rig (a
HumanIK BVH, 24 joints) without the footskate cleanup: source forward
kinematics, every target joint's rotation and Euler angles, continuity and
the root.  The plan (joint map, rest corrections) is worked out once per
pair of skeletons and kept, as for a batch of takes; its own cost is the
"plan" case.  The numpy twin does the same work with one numpy call per
joint over all frames (tests/retarget_twin.py).
"""

import numpy as np
import pytest

import motiontheater as mt
from conftest import DATA
from motiontheater.characters.retarget import _cached_plan, _root_positions, _unroll
from motiontheater.model.rig import rest_values
from twins import retarget as retarget_twin

FAST = dict(rounds=30, iterations=1, warmup_rounds=2)
SLOW = dict(rounds=5, iterations=1, warmup_rounds=1)
TAKE = "retarget cmu/01_01 onto walk01's rig, no cleanup (2751 frames)"
PLAN = "plan cmu 01.asf -> walk01.bvh (joint map, rest corrections)"


@pytest.fixture(scope="module")
def take():
    if not DATA.is_dir():
        pytest.skip(f"real capture corpus not found at {DATA}")
    motion = mt.read_take(DATA / "cmu" / "01_01.amc")
    target = mt.read_bvh(DATA / "bvh" / "walk01.bvh").skeleton
    return motion, target, mt.plan_retarget(motion.skeleton, target)


def joint_frames(take) -> int:
    """Frames times target joints: the amount of work."""
    motion, target, _ = take
    return motion.frames * len(target.joint_names)


def numpy_retarget(motion: mt.Motion, plan) -> mt.Motion:
    """retarget() with the numpy twin in place of the kernel."""
    target = plan.target
    values = rest_values(target, motion.frames)
    rotations = retarget_twin.retarget_rotations(
        motion.values, plan.source_tree, target.tree, len(target.channels), plan.kernel
    )
    turns = [c for c, (_, d) in enumerate(target.channels) if d.startswith("r")]
    values[:, turns] = rotations[:, turns]
    _unroll(target, values, plan.kernel.follow)
    _root_positions(motion, plan, values)
    return mt.Motion(target, values, frame_rate=motion.frame_rate, first_frame=motion.first_frame, header=())


@pytest.mark.parametrize("threads", {"all cores": None, "1 thread": 1})
def test_retarget(benchmark, record, take, threads):
    motion, target, plan = take
    workers = {"all cores": None, "1 thread": 1}[threads]
    result = benchmark.pedantic(mt.retarget, (motion, target), dict(cleanup=False, workers=workers), **FAST)
    np.testing.assert_allclose(result.values, numpy_retarget(motion, plan).values, rtol=0, atol=1e-8)
    record(f"{TAKE}, {threads}", "mtcore", joint_frames(take), unit="M joint-frames", target="<= 10 ms, >= 10x numpy")


def test_numpy_retarget(benchmark, record, take):
    motion, _, plan = take
    benchmark.pedantic(numpy_retarget, (motion, plan), **SLOW)
    for threads in ("all cores", "1 thread"):
        record(f"{TAKE}, {threads}", "numpy twin", joint_frames(take), unit="M joint-frames")


def test_plan(benchmark, record, take):
    motion, target, _ = take

    def plan():
        _cached_plan.cache_clear()
        return mt.plan_retarget(motion.skeleton, target)

    benchmark.pedantic(plan, **SLOW)
    record(PLAN, "mtcore", 1, unit="plans")
