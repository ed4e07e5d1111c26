"""The thesis scene (24,000 values) and the one-hour capture with every peer, in one run.

Run: python -m pytest benchmarks/bench_filters.py benchmarks/bench_thesis.py
The scene is measured twice: synthetic (267 x 90, the thesis's 30 joints x 3
rotations) and real (the first 267 frames of cmu/01_01.amc, its 59 rotation
channels).  A plain Python loop is too slow for the hour (minutes per call),
so it is timed on the scene only; bottleneck joins the hour's rows of
bench_filters.py, which time mtcore, scipy and the copy ceiling.
"""

import numpy as np
import pytest

import motiontheater as mt
from conftest import DATA
from motiontheater.cli import bench

SIZES = [3, 5, 7]
PEERS = bench.peers()


def scenes():
    found = {"synthetic (267, 90)": bench.noisy_rotations(seconds=267 / 120, channels=90)[1]}
    if DATA.is_dir():
        take = mt.read_amc(DATA / "cmu" / "01_01.amc", mt.read_asf(DATA / "cmu" / "01.asf"))
        found["01_01.amc frames 1-267 (267, 59)"] = bench.scene_from_take(take)
    return found


SCENES = scenes()


@pytest.mark.parametrize("size", SIZES)
@pytest.mark.parametrize("kind", bench.KINDS)
@pytest.mark.parametrize("scene", SCENES)
@pytest.mark.parametrize("who", ["mtcore", "plain Python", "scipy", "bottleneck", "numpy.copyto"])
def test_thesis_scene(benchmark, record, scene, kind, size, who):
    x = SCENES[scene]
    if who == "mtcore":
        fn, plan = (lambda: bench.OURS[kind](x, size, axis=0, mode="nearest")), dict(rounds=2000, warmup_rounds=50)
    elif who == "plain Python":
        rows = x.tolist()
        fn, plan = (lambda: bench.python_filter(kind, rows, size)), dict(rounds=5)
    elif who == "numpy.copyto":
        out = np.empty_like(x)
        fn, plan = (lambda: np.copyto(out, x)), dict(rounds=2000, warmup_rounds=50)
    else:
        peer = PEERS.get(who)
        if peer is None or peer(kind, x, size) is None:
            pytest.skip(f"{who} is not installed or has no {kind} filter")
        fn, plan = (lambda: peer(kind, x, size)), dict(rounds=200, warmup_rounds=5)
    benchmark.pedantic(fn, iterations=1, **plan)
    record(f"thesis scene {scene}, {kind} {size}", who, x.size, target="<= 60 us, >= 500x plain Python")


@pytest.fixture(scope="module")
def hour():
    return np.random.default_rng(0).standard_normal(bench.HOUR).cumsum(axis=0)


@pytest.mark.parametrize("size", SIZES)
@pytest.mark.parametrize("kind", ["mean", "median"])
def test_hour_bottleneck(benchmark, record, hour, kind, size):
    peer = PEERS.get("bottleneck")
    if peer is None:
        pytest.skip("bottleneck is not installed")
    benchmark.pedantic(lambda: peer(kind, hour, size), rounds=2, iterations=1)
    name = {"mean": "uniform", "median": "median"}[kind]
    for threads in ("all cores", "1 thread"):
        record(f"hour axis 0, fresh, {name} {size}, {threads}", "bottleneck", hour.size)
