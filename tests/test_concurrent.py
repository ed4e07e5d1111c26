"""Every C entry point called from eight threads at once on different inputs, each result equal
bit for bit to its serial result (the model: PyWavelets' test_concurrent.py).  cffi releases the
GIL for every call, so the kernels really run together: a static scratch buffer would show here."""

import threading
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import mtcore
from twins import TWINS, exact

THREADS = 8


def inputs(name: str) -> list[tuple]:
    """Eight different argument tuples: from eight seeds, each a different one of the twin's cases."""
    out = []
    for seed in range(THREADS):
        cases = [c for c in TWINS[name].cases(np.random.default_rng(seed)) if not _empty(c)]
        out.append(cases[seed * 7919 % len(cases)])
    return out


def _empty(case: tuple) -> bool:
    return any(isinstance(a, np.ndarray) and a.size == 0 for a in case)


@pytest.mark.parametrize("name", sorted(TWINS))
def test_entry_point_from_eight_threads(name):
    fast = TWINS[name].fast
    cases = inputs(name)
    serial = [fast(*case) for case in cases]
    start = threading.Barrier(THREADS)

    def call(case):
        start.wait()  # all eight enter C together
        return [fast(*case) for _ in range(20)]

    with ThreadPoolExecutor(THREADS) as pool:
        results = list(pool.map(call, cases))
    for want, got in zip(serial, results):
        for again in got:
            exact(again, want)


def test_threads_share_the_parallel_pool():
    """Calls that split over mtcore's own pool (large arrays), made from eight threads at once."""
    x = np.random.default_rng(0).standard_normal((1 << 17, 8))
    serial = [mtcore.uniform_filter1d(x * (i + 1), 5, axis=0, workers=-1) for i in range(THREADS)]
    with ThreadPoolExecutor(THREADS) as pool:
        results = list(pool.map(lambda i: mtcore.uniform_filter1d(x * (i + 1), 5, axis=0, workers=-1), range(THREADS)))
    for want, got in zip(serial, results):
        exact(got, want)


@pytest.mark.parametrize(("processes", "share"), [(1, 8), (2, 4), (3, 2), (8, 1), (16, 1)])
def test_a_process_that_shares_the_cores_splits_its_calls_over_its_share(monkeypatch, processes, share):
    from mtcore import _parallel

    monkeypatch.setattr(_parallel.os, "sched_getaffinity", lambda pid: set(range(8)), raising=False)
    monkeypatch.setattr(_parallel, "_share", None)
    assert mtcore.cpu_count() == 8
    mtcore.share_cores(processes)
    assert mtcore.cpu_count() == share
    assert _parallel.thread_count(None, large=True) == share
    mtcore.share_cores(1)  # a share is of the cores, not of an earlier share
    assert mtcore.cpu_count() == 8
