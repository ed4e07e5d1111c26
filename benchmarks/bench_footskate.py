"""Speed of footskate detection and cleanup against its vectorised numpy twin, and on an hour of capture.

Run: python -m pytest benchmarks/bench_footskate.py
The take is cmu/01_01 (2,751 frames, 120 Hz, 31 joints), end to end from
the motion: legs, upper-body kinematics, floor fit, footplant detection,
targets, the cleanup's phases and the channels written back.  The numpy
peer is the same pipeline with the kernels' phases in whole-array numpy
(tests/twins/footskate.py: leg kinematics, the contact points' speeds, the
footplants' runs, plan, root, solve, the channels written back).  The hour
is 01_01 tiled to 432,000 frames (one hour at 120 Hz, 62 channels), on one
core (the kernels run in the calling thread).
"""

from unittest import mock

import numpy as np
import pytest

import motiontheater as mt
from conftest import DATA
from motiontheater.feet.footskate import clean_footskate
from mtcore import footskate as kernels
from twins import footskate as footskate_twin

TAKE = "detect + clean up cmu/01_01 (2751 frames)"
HOUR = "detect + clean up one hour at 120 Hz (432,000 frames)"


@pytest.fixture(scope="module")
def take():
    if not DATA.is_dir():
        pytest.skip(f"real capture corpus not found at {DATA}")
    return mt.read_amc(DATA / "cmu" / "01_01.amc", mt.read_asf(DATA / "cmu" / "01.asf"))


def numpy_clean(motion):
    with (
        mock.patch.object(kernels, "leg_points", footskate_twin.leg_points),
        mock.patch.object(kernels, "cleanup", footskate_twin.cleanup),
        mock.patch.object(kernels, "write_channels", footskate_twin.write_channels),
        mock.patch.object(kernels, "point_speeds", footskate_twin.point_speeds),
        mock.patch.object(kernels, "plant_masks", footskate_twin.plant_masks),
    ):
        return clean_footskate(motion)


def test_cleanup_mtcore(benchmark, record, take):
    result = benchmark.pedantic(clean_footskate, (take,), rounds=30, iterations=1, warmup_rounds=2)
    assert len(result.contacts) > 50
    record(TAKE, "mtcore", take.frames, target="<= 20 ms, >= 20x numpy", unit="M frames")


def test_cleanup_numpy(benchmark, record, take):
    result = benchmark.pedantic(numpy_clean, (take,), rounds=5, iterations=1, warmup_rounds=1)
    fast = clean_footskate(take)
    assert result.contacts == fast.contacts
    np.testing.assert_allclose(result.root_offsets, fast.root_offsets, rtol=0, atol=1e-9)
    record(TAKE, "numpy", take.frames, unit="M frames")


def test_cleanup_an_hour(benchmark, record, take):
    reps = -(-432_000 // take.frames)
    hour = take.replace(values=np.tile(take.values, (reps, 1))[:432_000])
    result = benchmark.pedantic(clean_footskate, (hour,), {"workers": 1}, rounds=3, iterations=1, warmup_rounds=0)
    assert result.motion.frames == 432_000
    record(HOUR, "mtcore", hour.frames, target="< 3 s on one core", unit="M frames")
