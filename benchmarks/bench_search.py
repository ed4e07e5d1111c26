"""Speed of mtcore.search against brute force and scipy's cKDTree, in one run.

Run: python -m pytest benchmarks/bench_search.py
Nearest neighbours over the 1-hour 120 Hz capture (432,000 x 62, a random walk as motion
is smooth): the k-d tree against the same kernel with one leaf (the C linear scan, the same
distance code), numpy's brute force and scipy.spatial.cKDTree.  DTW search of a 1-second
query (120 frames, band 12) in 10 minutes (72,000 x 62) against warping every window
(mt_dtw per window, timed over the first 2,000 and compared as windows per second).
"""

import numpy as np
import pytest

from conftest import NOTES
from mtcore import search as ms

HOUR = (432_000, 62)
FAST = dict(rounds=5, iterations=1, warmup_rounds=1)
SLOW = dict(rounds=2, iterations=1)
QUERIES = 1000
K = 10


@pytest.fixture(scope="module")
def hour():
    return np.random.default_rng(0).standard_normal(HOUR).cumsum(axis=0)


@pytest.fixture(scope="module")
def queries(hour):
    """Frames of the hour a little off their rows, as a pose of another take near one of this one."""
    rng = np.random.default_rng(1)
    return hour[rng.integers(0, len(hour), QUERIES)] + rng.normal(0, 0.1, (QUERIES, HOUR[1]))


@pytest.fixture(scope="module")
def tree(hour):
    return ms.KDTree(hour)


def test_knn_build(benchmark, record, hour):
    benchmark.pedantic(ms.KDTree, (hour,), **SLOW)
    record("KDTree build (432000, 62)", "mtcore", hour.size)


@pytest.mark.parametrize("who", ["mtcore", "C scan", "numpy", "cKDTree"])
def test_knn_query(benchmark, record, hour, queries, tree, who):
    case = f"{K} nearest of {QUERIES} queries in (432000, 62), 1 thread"
    if who == "mtcore":
        benchmark.pedantic(tree.query, (queries, K), {"workers": 1}, **FAST)
        record(case, who, QUERIES, unit="M queries")
    elif who == "C scan":
        scan = ms.KDTree(hour, len(hour))  # one leaf
        few = queries[:20]
        benchmark.pedantic(scan.query, (few, K), {"workers": 1}, **SLOW)
        np.testing.assert_array_equal(scan.query(few, K).indices, tree.query(few, K).indices)
        record(case, who, len(few), unit="M queries")
    elif who == "numpy":
        few = queries[:3]

        def brute():
            for q in few:
                d = ((hour - q) ** 2).sum(axis=1)
                np.argpartition(d, K)[:K]

        benchmark.pedantic(brute, **SLOW)
        record(case, who, len(few), unit="M queries")
    else:
        spatial = pytest.importorskip("scipy.spatial")
        peer = spatial.cKDTree(hour)
        benchmark.pedantic(peer.query, (queries, K), {"workers": 1}, **FAST)
        _, indices = peer.query(queries[:50], K)
        np.testing.assert_array_equal(indices, tree.query(queries[:50], K).indices)
        record(case, who, QUERIES, unit="M queries")


@pytest.fixture(scope="module")
def ten_minutes(hour):
    return np.ascontiguousarray(hour[:72_000])


@pytest.fixture(scope="module")
def query(ten_minutes):
    return ten_minutes[30_000:30_120] + np.random.default_rng(2).normal(0, 0.3, (120, HOUR[1]))


@pytest.mark.parametrize("who", ["mtcore", "every window"])
def test_dtw_search(benchmark, record, ten_minutes, query, who):
    case = "10 nearest windows by DTW (m 120, band 12) in (72000, 62)"
    windows = len(ten_minutes) - len(query) + 1
    if who == "mtcore":
        hits = benchmark.pedantic(ms.dtw_search, (query, ten_minutes, K, 12), **SLOW)
        record(case, who, windows, unit="M windows")
        NOTES.append(
            f"dtw_search, {case}: of {windows} windows {hits.warped} warped, {hits.abandoned} abandoned, "
            f"{hits.pruned} pruned ({hits.pruned / windows:.1%})"
        )
        return
    first = 2000

    def every():
        return [ms.dtw(query, ten_minutes[s : s + len(query)], 12) for s in range(first)]

    benchmark.pedantic(every, **SLOW)
    record(case, who, first, unit="M windows")
