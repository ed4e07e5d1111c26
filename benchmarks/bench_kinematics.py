"""Speed of forward kinematics against upc-pymotion and a vectorised numpy FK, in one run.

Run: python -m pytest benchmarks/bench_kinematics.py
The take is cmu/01_01 (2751 frames, 31 joints): our read of the AMC plus
all positions, upc-pymotion's load of the same take's BVH plus its FK, and
the tests' numpy twin (one numpy call per bone over all frames).
"""

import pytest

import motiontheater as mt
from conftest import DATA
from mtcore.kinematics import forward_kinematics
from twins.kinematics import motion_kinematics as numpy_fk

FAST = dict(rounds=30, iterations=1, warmup_rounds=2)
SLOW = dict(rounds=5, iterations=1, warmup_rounds=1)
PIPELINE = "read cmu/01_01.amc + all positions"
KERNEL = "FK kernel alone, 2751 frames x 31 joints"


@pytest.fixture(scope="module")
def take():
    if not DATA.is_dir():
        pytest.skip(f"real capture corpus not found at {DATA}")
    skeleton = mt.read_asf(DATA / "cmu" / "01.asf")
    return skeleton, mt.read_amc(DATA / "cmu" / "01_01.amc", skeleton)


def transforms(motion):
    return motion.frames * len(motion.skeleton.joint_names)


def test_read_and_positions(benchmark, record, take):
    skeleton, motion = take

    def run():
        return mt.read_amc(DATA / "cmu" / "01_01.amc", skeleton).positions()

    assert benchmark.pedantic(run, **FAST).shape == (2751, 31, 3)
    record(
        PIPELINE,
        "mtcore",
        transforms(motion),
        unit="M transforms",
        target="<= 25 ms, >= 40x upc-pymotion, >= 20x numpy",
    )


def test_read_and_numpy_fk(benchmark, record, take):
    skeleton, motion = take
    benchmark.pedantic(lambda: numpy_fk(mt.read_amc(DATA / "cmu" / "01_01.amc", skeleton)), **SLOW)
    record(PIPELINE, "numpy FK", transforms(motion), unit="M transforms")


def test_upc_pymotion_load_and_fk(benchmark, record, take):
    bvh_module = pytest.importorskip("pymotion.io.bvh")
    from pymotion.ops.skeleton_np import fk

    def run():
        bvh = bvh_module.BVH()
        bvh.load(str(DATA / "cmu" / "01_01.bvh"))
        rotations, positions, parents, offsets, _, _ = bvh.get_data()
        return fk(rotations, positions[:, 0, :], offsets, parents)

    positions = benchmark.pedantic(run, **SLOW)[0]
    assert positions.shape == (2752, 31, 3)
    record(PIPELINE, "upc-pymotion", positions.shape[0] * positions.shape[1], unit="M transforms")


@pytest.mark.parametrize("threads", {"all cores": None, "1 thread": 1})
def test_fk_kernel(benchmark, record, take, threads):
    _, motion = take
    tree = motion.skeleton.tree
    workers = {"all cores": None, "1 thread": 1}[threads]
    benchmark.pedantic(forward_kinematics, (motion.values, tree), dict(workers=workers), **FAST)
    record(f"{KERNEL}, {threads}", "mtcore", transforms(motion), unit="M transforms", target=">= 20 M transforms/s")


def test_numpy_fk_kernel(benchmark, record, take):
    _, motion = take
    benchmark.pedantic(numpy_fk, (motion,), **SLOW)
    for threads in ("all cores", "1 thread"):
        record(f"{KERNEL}, {threads}", "numpy FK", transforms(motion), unit="M transforms")
