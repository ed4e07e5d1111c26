"""Speed of the mtcore filters against a memory copy and scipy.ndimage, in one run.

Run: python -m pytest benchmarks/bench_filters.py
The table printed at the end is the one in the closing notes of issue 2.
"""

from functools import partial

import numpy as np
import pytest
import scipy.ndimage as ndi

import mtcore

HOUR = (432_000, 62)  # one hour at 120 Hz, 62 channels
SCENE = (267, 90)  # the thesis's scene: 267 frames x 30 joints x 3 rotations
SIZES = [3, 5, 7]
OURS = {
    "median": mtcore.median_filter1d,
    "uniform": mtcore.uniform_filter1d,
    "binomial": mtcore.binomial_filter1d,
}
SCIPY = {
    "median": lambda x, size, axis, **kw: ndi.median_filter(x, size=size, axes=(axis,), **kw),
    "uniform": ndi.uniform_filter1d,
    "binomial": lambda x, size, axis, **kw: ndi.correlate1d(x, mtcore.pascal_weights(size), axis, **kw),
}
FAST = dict(rounds=10, iterations=1, warmup_rounds=1)
SLOW = dict(rounds=2, iterations=1)


@pytest.fixture(scope="module")
def hour():
    return np.random.default_rng(0).standard_normal(HOUR).cumsum(axis=0)


@pytest.fixture(scope="module")
def hour_t(hour):
    return np.ascontiguousarray(hour.T)


@pytest.fixture(scope="module")
def scene():
    return np.random.default_rng(1).standard_normal(SCENE).cumsum(axis=0)


def test_copy_ceilings(benchmark, record, hour):
    out = np.empty_like(hour)
    benchmark.pedantic(np.copyto, (out, hour), **FAST)
    record("numpy.copyto (432000, 62)", "copy", hour.size)


def test_fresh_copy_ceiling(benchmark, record, hour):
    benchmark.pedantic(hour.copy, **FAST)
    record("ndarray.copy (432000, 62)", "copy", hour.size)


# workers=None is the default (every core for arrays this large); workers=1 shows one core's share.
THREADS = {"all cores": None, "1 thread": 1}


@pytest.mark.parametrize("threads", THREADS)
@pytest.mark.parametrize("size", SIZES)
@pytest.mark.parametrize("name", OURS)
def test_hour_axis0_prealloc(benchmark, record, hour, name, size, threads):
    out = np.empty_like(hour)
    benchmark.pedantic(partial(OURS[name], workers=THREADS[threads]), (hour, size, 0, out), **FAST)
    record(
        f"hour axis 0, output=, {name} {size}, {threads}",
        "mtcore",
        hour.size,
        ceiling="numpy.copyto (432000, 62)",
        target=">= 40% of copy",
    )


@pytest.mark.parametrize("size", SIZES)
@pytest.mark.parametrize("name", OURS)
@pytest.mark.parametrize("who", ["scipy", "all cores", "1 thread"])
def test_hour_axis0_fresh(benchmark, record, hour, name, size, who):
    if who == "scipy":
        benchmark.pedantic(SCIPY[name], (hour, size, 0), **SLOW)
        for threads in THREADS:
            record(f"hour axis 0, fresh, {name} {size}, {threads}", "scipy", hour.size)
        return
    benchmark.pedantic(partial(OURS[name], workers=THREADS[who]), (hour, size, 0), **FAST)
    record(
        f"hour axis 0, fresh, {name} {size}, {who}",
        "mtcore",
        hour.size,
        ceiling="ndarray.copy (432000, 62)",
        target=">= 40% of copy, >= 10x scipy" + (" (median 30x)" if name == "median" else ""),
    )


@pytest.mark.parametrize("threads", THREADS)
@pytest.mark.parametrize("size", SIZES)
@pytest.mark.parametrize("name", OURS)
def test_hour_last_axis(benchmark, record, hour_t, name, size, threads):
    benchmark.pedantic(partial(OURS[name], workers=THREADS[threads]), (hour_t, size, -1), **FAST)
    record(
        f"(62, 432000) axis -1, {name} {size}, {threads}",
        "mtcore",
        hour_t.size,
        ceiling="ndarray.copy (432000, 62)",
        target=">= 200 M values/s",
    )


@pytest.mark.parametrize("size", SIZES)
@pytest.mark.parametrize("name", OURS)
@pytest.mark.parametrize("who", ["mtcore", "scipy"])
def test_thesis_scene(benchmark, record, scene, name, size, who):
    fn = OURS[name] if who == "mtcore" else SCIPY[name]
    benchmark.pedantic(fn, (scene, size, 0), rounds=2000, iterations=1, warmup_rounds=50)
    record(f"thesis scene (267, 90), {name} {size}", who, scene.size, target="<= 60 us per call")
