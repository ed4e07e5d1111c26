"""BVH speed: read + positions against upc-pymotion and the bvh package; scanning throughput.

Run: python -m pytest benchmarks/bench_bvh.py
cmu/01_01.bvh (2752 frames, 31 joints, 96 channels): our read plus every
joint's position per frame; upc-pymotion's load plus its FK; the bvh
package reading every channel of every frame through its per-channel
access (no FK at all).  Scanning: 01_01.bvh's frames repeated to about 100 MB.
"""

import pytest

import motiontheater as mt
from conftest import DATA

CASE = "read cmu/01_01.bvh + all positions"


@pytest.fixture(scope="module")
def take():
    if not DATA.is_dir():
        pytest.skip(f"real capture corpus not found at {DATA}")
    return DATA / "cmu" / "01_01.bvh"


def test_read_and_positions(benchmark, record, take):
    positions = benchmark.pedantic(lambda: mt.read_bvh(take).positions(), rounds=30, iterations=1, warmup_rounds=2)
    assert positions.shape == (2752, 38, 3)  # the root, 31 joints, 6 end sites
    record(CASE, "mtcore", take.stat().st_size, unit="MB", target=">= 40x upc-pymotion, >= 100x bvh package")


def test_upc_pymotion(benchmark, record, take):
    bvh_module = pytest.importorskip("pymotion.io.bvh")
    from pymotion.ops.skeleton_np import fk

    def run():
        bvh = bvh_module.BVH()
        bvh.load(str(take))
        rotations, positions, parents, offsets, _, _ = bvh.get_data()
        return fk(rotations, positions[:, 0, :], offsets, parents)

    benchmark.pedantic(run, rounds=5, iterations=1, warmup_rounds=1)
    record(CASE, "upc-pymotion", take.stat().st_size, unit="MB")


def test_bvh_package_per_channel(benchmark, record, take):
    bvh_package = pytest.importorskip("bvh")

    def run():
        mocap = bvh_package.Bvh(take.read_text())
        joints = mocap.get_joints_names()
        channels = {j: mocap.joint_channels(j) for j in joints}
        return [[mocap.frame_joint_channels(f, j, channels[j]) for j in joints] for f in range(mocap.nframes)]

    benchmark.pedantic(run, rounds=1, iterations=1)
    record(CASE, "bvh package", take.stat().st_size, unit="MB")


@pytest.fixture(scope="module")
def big(tmp_path_factory, take):
    text = take.read_bytes()
    head, body = text.split(b"Frame Time:")
    time_line, frames = body.split(b"\n", 1)
    rows = frames.strip().splitlines()
    copies = 100_000_000 // len(frames) + 1
    path = tmp_path_factory.mktemp("bvh") / "big.bvh"
    path.write_bytes(
        head.replace(b"Frames: 2752", b"Frames: %d" % (len(rows) * copies))
        + b"Frame Time:"
        + time_line
        + b"\n"
        + (b"\n".join(rows) + b"\n") * copies
    )
    return path


def test_scanning_throughput(benchmark, record, big):
    motion = benchmark.pedantic(mt.read_bvh, (big,), rounds=3, iterations=1, warmup_rounds=1)
    assert motion.frames > 100_000
    record("read a 100 MB BVH", "mtcore", big.stat().st_size, unit="MB", target=">= 300 MB/s")
