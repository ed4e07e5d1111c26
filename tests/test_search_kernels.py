"""Search by example (mtcore.search: csrc/dtw.c, knn.c, features.c) against slow twins (tests/twins/search.py)
and brute force: the searches must find exactly what computing every distance and sorting finds."""

import math
import re

import numpy as np
import pytest

from mtcore import search as ms
from mtcore._cdata import c_array
from mtcore._mtcore import ffi, lib
from mtcore._status import check
from twins import search as twin

SEEDS = range(6)


def walk(rng, frames, dims):
    return rng.normal(size=(frames, dims)).cumsum(axis=0)


def close(got, want):
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12)


# ---------------------------------------------------------------------------
# envelope, LB_Keogh, DTW


@pytest.mark.parametrize("frames", [0, 1, 2, 3, 8, 17, 100])
@pytest.mark.parametrize("radius", [0, 1, 2, 5, 99, 10**9])
def test_envelope_equals_the_sliced_windows(rng, frames, radius):
    for dims in (1, 4):
        x = walk(rng, frames, dims)
        upper, lower = ms.lb_envelope(x, radius)
        want = twin.lb_envelope(x, radius)
        np.testing.assert_array_equal(upper, want[0])
        np.testing.assert_array_equal(lower, want[1])


def test_envelope_of_runs_of_equal_and_monotonic_samples():
    """The deques' hard cases: ties (kept once), a rising and a falling line (each sample displaces all)."""
    for x in (np.zeros(9), np.arange(12.0), -np.arange(12.0), np.array([3, 3, 1, 3, 3, 5, 5, 0, 5.0])):
        for radius in (0, 1, 3, 20):
            got = ms.lb_envelope(x, radius)
            want = twin.lb_envelope(x, radius)
            np.testing.assert_array_equal(got.upper, want[0])
            np.testing.assert_array_equal(got.lower, want[1])


@pytest.mark.parametrize("seed", SEEDS)
def test_lb_keogh_equals_its_twin_and_bounds_dtw(seed):
    rng = np.random.default_rng(seed)
    for frames in (0, 1, 2, 7, 30):
        for dims in (1, 2, 5, 9):
            query, candidate = walk(rng, frames, dims), walk(rng, frames, dims)
            for radius in (0, 1, 4, frames):
                env = ms.lb_envelope(query, radius)
                bound = ms.lb_keogh(candidate, env)
                close(bound, twin.lb_keogh(candidate, *env))
                # the pruning relies on this after rounding too: never above the distance computed
                assert bound <= ms.dtw(query, candidate, radius)


def test_lb_keogh_stops_past_its_threshold(rng):
    query, candidate = walk(rng, 50, 3), walk(rng, 50, 3) + 5
    env = ms.lb_envelope(query, 2)
    full = ms.lb_keogh(candidate, env)
    for threshold in (0.0, full / 10, full / 2, full * 0.999, full, math.inf):
        partial = ms.lb_keogh(candidate, env, threshold)
        close(partial, twin.lb_keogh(candidate, *env, threshold))
        assert partial <= full
        assert partial == full or partial > threshold


@pytest.mark.parametrize("seed", SEEDS)
def test_dtw_equals_its_twin(seed):
    rng = np.random.default_rng(seed)
    for m, n in ((0, 0), (0, 4), (3, 0), (1, 1), (1, 6), (5, 5), (6, 5), (8, 13), (21, 20), (30, 30)):
        for dims in (1, 3):
            a, b = walk(rng, m, dims), walk(rng, n, dims)
            for radius in (0, 1, 2, 5, 40, None):
                got = ms.dtw(a, b, radius)
                want = twin.dtw(a, b, radius)
                if math.isinf(want):
                    assert got == want
                else:
                    close(got, want)
                assert got == ms.dtw(b, a, radius)  # the same cells, summed in the same order


def test_dtw_edges():
    a = np.arange(6.0)
    assert ms.dtw(a, a, 0) == 0.0
    assert ms.dtw(np.zeros((0, 2)), np.zeros((0, 2))) == 0.0
    assert ms.dtw(np.zeros((0, 2)), np.ones((3, 2))) == math.inf
    assert ms.dtw(a, a[:3], 2) == math.inf  # the band misses the corner
    assert ms.dtw(a, a[:3], 3) < math.inf
    b = a[::-1].copy()
    assert ms.dtw(a, b, 0) == ((a - b) ** 2).sum()  # no warping: squared Euclidean
    assert ms.dtw(a, b, None) == ms.dtw(a, b, 6) == ms.dtw(a, b, 10**12)
    assert ms.dtw([1.0, 2, 3], [1.0, 1, 2, 2, 3, 3]) == 0.0  # warping absorbs repeated frames


def test_dtw_abandons_only_above_its_threshold(rng):
    for _ in range(40):
        a, b = walk(rng, 12, 2), walk(rng, 15, 2)
        full = ms.dtw(a, b, 4)
        threshold = float(rng.uniform(0, 2 * full))
        got = ms.dtw(a, b, 4, threshold)
        assert got == twin.dtw(a, b, 4, threshold) or math.isclose(got, twin.dtw(a, b, 4, threshold))
        assert got == full or (got == math.inf and full > threshold)
        assert ms.dtw(a, b, 4, full) == full  # a tie is kept


# ---------------------------------------------------------------------------
# the subsequence search


def brute_force(query, series, k, radius, starts):
    """mt_dtw at every candidate (the same sums as the search's), sorted by (distance, start)."""
    m = len(query)
    found = sorted((ms.dtw(query, series[s : s + m], m if radius is None else radius), int(s)) for s in starts)[:k]
    return [s for _, s in found], [d for d, _ in found]


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("m", [1, 2, 7, 16])
@pytest.mark.parametrize("stored", [np.float64, np.float32])
def test_search_equals_brute_force(seed, m, stored):
    """A float32 series is searched as the float64 of its values: the same sums, bit for bit."""
    rng = np.random.default_rng(seed)
    for n, dims in ((m, 1), (m + 1, 2), (40, 1), (131, 3)):
        series = walk(rng, n, dims).astype(stored)
        start = int(rng.integers(0, n - m + 1))
        query = series[start : start + m] + rng.normal(0, 0.5, (m, dims))
        for k in (1, 2, 5, 1000):
            for radius in (0, 1, 3, m, None):
                for starts in (None, np.flatnonzero(rng.random(n - m + 1) < 0.3)):
                    hits = ms.dtw_search(query, series, k, radius, starts)
                    candidates = range(n - m + 1) if starts is None else starts
                    want_starts, want_distances = brute_force(query, series.astype(np.float64), k, radius, candidates)
                    assert hits.starts.tolist() == want_starts
                    assert hits.distances.tolist() == want_distances  # bit for bit: the same kernel's sums
                    assert hits.warped + hits.abandoned + hits.pruned == len(candidates)
                    assert len(hits.bounds) == len(candidates)


def test_search_equals_the_numpy_twin(rng):
    series = walk(rng, 90, 2)
    for m, k, radius in ((5, 3, 1), (12, 4, 3), (12, 1, None), (1, 6, 0)):
        query = series[30 : 30 + m] + rng.normal(0, 0.2, (m, 2))
        hits = ms.dtw_search(query, series, k, radius)
        want_starts, want_distances = twin.dtw_search(query, series, k, radius)
        assert hits.starts.tolist() == want_starts.tolist()
        close(hits.distances, want_distances)


def test_search_breaks_ties_by_the_lower_start(rng):
    """Integer samples sum exactly: the same window three times, and windows at equal distances."""
    piece = np.round(walk(rng, 30, 2))
    series = np.concatenate([piece, piece, np.round(walk(rng, 10, 2)), piece])
    for k in (1, 3, 8, 40):
        for radius in (0, 2):
            hits = ms.dtw_search(piece[5:12], series, k, radius)
            assert hits.starts.tolist() == brute_force(piece[5:12], series, k, radius, range(len(series) - 6))[0]
            assert hits.starts[:3].tolist() == [5, 35, 75] or k < 3
    flat = np.zeros((20, 1))
    hits = ms.dtw_search(np.zeros((4, 1)), flat, 5, 1)
    assert hits.starts.tolist() == [0, 1, 2, 3, 4] and hits.distances.tolist() == [0.0] * 5


@pytest.mark.parametrize("seed", range(100))
def test_search_keeps_ties_whose_bound_equals_the_kth_distance(seed):
    """Samples of 0, 1, 2 make distances tie all the time, and bounds equal to them: a window whose
    bound is exactly the k-th best so far may still win on its lower start, so it must be warped."""
    rng = np.random.default_rng(seed)
    series = rng.integers(0, 3, (40, 1)).astype(float)
    query = rng.integers(0, 3, (4, 1)).astype(float)
    for k in (1, 2, 3):
        for radius in (0, 1, 2):
            hits = ms.dtw_search(query, series, k, radius)
            assert (hits.starts.tolist(), hits.distances.tolist()) == brute_force(query, series, k, radius, range(37))


def test_bounds_never_exceed_the_distances(rng):
    series = walk(rng, 300, 3)
    query = series[100:140] + rng.normal(0, 0.3, (40, 3))
    hits = ms.dtw_search(query, series, 3, 4)
    distances = np.array([ms.dtw(query, series[s : s + 40], 4) for s in range(len(series) - 39)])
    assert (hits.bounds <= distances).all()


def test_search_prunes_on_motion_like_data(rng):
    series = walk(rng, 3000, 4)
    query = series[1200:1260] + rng.normal(0, 0.2, (60, 4))
    hits = ms.dtw_search(query, series, 5, 6)
    assert hits.starts[0] == 1200 or abs(int(hits.starts[0]) - 1200) <= 3
    assert hits.pruned > 0.5 * len(hits.bounds), (hits.warped, hits.abandoned, hits.pruned)


def test_search_of_nothing():
    empty = ms.dtw_search(np.zeros((5, 2)), np.zeros((3, 2)), 2)  # no window fits
    assert empty.starts.shape == (0,) and empty.distances.shape == (0,) and empty.bounds.shape == (0,)
    none = ms.dtw_search(np.zeros((2, 2)), np.zeros((8, 2)), 2, starts=[])
    assert none.starts.shape == (0,)
    zero = ms.dtw_search(np.zeros((0, 2)), np.ones((3, 2)), 2)  # empty windows: all at 0, the first starts win
    assert zero.starts.tolist() == [0, 1] and zero.distances.tolist() == [0.0, 0.0]


def test_search_leaves_its_inputs_alone(rng):
    series, query = walk(rng, 100, 2), walk(rng, 10, 2)
    series.flags.writeable = query.flags.writeable = False
    before = series.copy(), query.copy()
    ms.dtw_search(query, series, 3, 2)
    np.testing.assert_array_equal(series, before[0])
    np.testing.assert_array_equal(query, before[1])


def test_search_bad_input(rng):
    series, query = walk(rng, 50, 2), walk(rng, 5, 2)
    holed = series.copy()
    holed[17, 1] = np.nan
    with pytest.raises(ValueError, match=r"series must be finite .* at series\[17, 1\]"):
        ms.dtw_search(query, holed)
    with pytest.raises(ValueError, match="query must be finite"):
        ms.dtw_search(np.full((3, 2), np.inf), series)
    with pytest.raises(ValueError, match="k must be at least 1, got 0"):
        ms.dtw_search(query, series, 0)
    with pytest.raises(ValueError, match="radius must be at least 0"):
        ms.dtw_search(query, series, 1, -1)
    with pytest.raises(ValueError, match=r"series must be two-dimensional of shape \(any, 2\)"):
        ms.dtw_search(query, walk(rng, 50, 3))
    with pytest.raises(ValueError, match="strictly increasing"):
        ms.dtw_search(query, series, 1, 1, [3, 3])
    with pytest.raises(ValueError, match=r"starts must lie in 0 \.\. 45"):
        ms.dtw_search(query, series, 1, 1, [46])
    with pytest.raises(ValueError, match="no window"):
        ms.dtw_search(walk(rng, 60, 2), series, 1, 1, [0])
    with pytest.raises(TypeError, match="real numbers"):
        ms.dtw_search(query.astype(complex), series)
    with pytest.raises(TypeError, match="k must be an integer"):
        ms.dtw_search(query, series, 1.5)
    with pytest.raises(ValueError, match="threshold must be"):
        ms.dtw(query, query, 1, math.nan)
    with pytest.raises(ValueError, match="the envelope must have the candidate's shape"):
        ms.lb_keogh(query, ms.lb_envelope(series, 1))


# ---------------------------------------------------------------------------
# nearest neighbours


def assert_neighbours(tree_points, leaf, queries, k, exclude=None, workers=1):
    got = ms.KDTree(tree_points, leaf).query(queries, k, exclude=exclude, workers=workers)
    want = twin.knn(tree_points, queries, k, exclude)
    np.testing.assert_array_equal(got.indices, want[0])
    close(got.distances, want[1])


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("n", [0, 1, 2, 3, 10, 33, 64, 500])
@pytest.mark.parametrize("stored", [np.float64, np.float32])
def test_knn_equals_brute_force(seed, n, stored):
    rng = np.random.default_rng(seed)
    for dims in (1, 2, 7, 30):
        points = walk(rng, n, dims).astype(stored)
        queries = np.concatenate([points[:3], walk(rng, 5, dims), points[-2:] + 1e-3])
        for leaf in (1, 4, 32, 1000):
            for k in (1, 4, n + 3):
                assert_neighbours(points, leaf, queries, k)


def test_knn_ties_go_to_the_lower_row():
    """A grid twice over: every distance has many equal ones, and each point its duplicate."""
    grid = np.array([[x, y, z] for x in range(5) for y in range(4) for z in range(3)], float)
    points = np.concatenate([grid, grid[::-1]])
    queries = np.concatenate([grid, grid + 0.5, grid[:7] * 0.5])
    for leaf in (1, 2, 5, 16):
        for k in (1, 2, 6, 27, 200):
            assert_neighbours(points, leaf, queries, k)


def test_knn_of_equal_points():
    points = np.ones((100, 3))
    got = ms.KDTree(points, 4).query(np.zeros(3), 5)
    assert got.indices.tolist() == [0, 1, 2, 3, 4] and got.distances.tolist() == [3.0] * 5


def test_knn_excludes_rows_per_query(rng):
    points = walk(rng, 400, 6)
    rows = np.arange(0, 400, 7)
    for width in (0, 1, 5):
        exclude = np.stack([np.maximum(rows - width, 0), rows + width + 1], axis=1)
        got = ms.KDTree(points, 8).query(points[rows], 3, exclude=exclude, workers=1)
        assert not (np.abs(got.indices - rows[:, None]) <= width).any()
        assert_neighbours(points, 8, points[rows], 3, exclude)
    assert_neighbours(points, 8, points[:4], 3, np.array([[0, 400], [0, 398], [5, 5], [10**6, 10**7]]))
    everything = ms.KDTree(points[:5], 2).query(points[:1], 3, exclude=[[0, 4]])
    assert everything.indices.tolist() == [[4, -1, -1]] and everything.distances[0, 1:].tolist() == [math.inf] * 2


def test_knn_shapes_and_threads(rng):
    points = walk(rng, 5000, 12)
    tree = ms.KDTree(points, 16)
    one = tree.query(points[10], 4)
    assert one.indices.shape == (4,) and one.indices[0] == 10
    many = tree.query(points[:600] + 0.01, 4, workers=1)
    threaded = tree.query(points[:600] + 0.01, 4, workers=3)
    np.testing.assert_array_equal(many.indices, threaded.indices)
    np.testing.assert_array_equal(many.distances, threaded.distances)
    assert tree.query(np.zeros((0, 12)), 3).indices.shape == (0, 3)
    assert ms.KDTree(np.zeros((0, 12))).query(points[:2], 3).indices.shape == (2, 0)
    assert tree.query(points[:2], 10**6).indices.shape == (2, 5000)


def assert_splits(tree, points, node, lo, hi, level):
    """Rows lo .. mid-1 of the node at most its split value in its dimension, mid .. hi-1 at least."""
    if level == tree.depth:
        return
    mid = lo + (hi - lo) // 2
    dim, value = int(tree.split_dim[node]), tree.split_value[node]
    rows = tree.index.astype(np.intp)
    assert (points[rows[lo:mid], dim] <= value).all() and (points[rows[mid:hi], dim] >= value).all()
    assert_splits(tree, points, 2 * node + 1, lo, mid, level + 1)
    assert_splits(tree, points, 2 * node + 2, mid, hi, level + 1)


def test_knn_tree_splits_its_rows(rng):
    """The tree's invariants, which the queries' pruning relies on; leaves no larger than asked, and no deeper."""
    points = np.round(walk(rng, 777, 5))
    for leaf in (1, 3, 10, 1000):
        tree = ms.KDTree(points, leaf)
        assert sorted(tree.index.tolist()) == list(range(777))
        assert math.ceil(777 / 2**tree.depth) <= leaf
        assert tree.depth == 0 or math.ceil(777 / 2 ** (tree.depth - 1)) > leaf
        assert_splits(tree, points, 0, 0, 777, 0)


def test_knn_leaves_its_inputs_alone(rng):
    points, queries = walk(rng, 300, 4), walk(rng, 9, 4)
    before = points.copy(), queries.copy()
    tree = ms.KDTree(points, 8)
    points[:] = 0  # the tree holds its own copy
    got = tree.query(queries, 2)
    want = twin.knn(before[0], before[1], 2)
    np.testing.assert_array_equal(got.indices, want[0])
    np.testing.assert_array_equal(queries, before[1])


def test_knn_bad_input(rng):
    points = walk(rng, 50, 3)
    holed = points.copy()
    holed[4, 2] = np.nan
    with pytest.raises(ValueError, match=r"points must be finite .* at points\[4, 2\]"):
        ms.KDTree(holed)
    tree = ms.KDTree(points)
    with pytest.raises(ValueError, match="queries must be finite"):
        tree.query(holed[:5])
    with pytest.raises(ValueError, match=r"queries must be two-dimensional of shape \(any, 3\)"):
        tree.query(np.zeros((2, 4)))
    with pytest.raises(ValueError, match="k must be at least 1"):
        tree.query(points[:1], 0)
    with pytest.raises(ValueError, match="leaf_size must be at least 1"):
        ms.KDTree(points, 0)
    with pytest.raises(ValueError, match="at least one column"):
        ms.KDTree(np.zeros((4, 0)))
    with pytest.raises(ValueError, match=r"exclude must be two-dimensional of shape \(2, 2\)"):
        tree.query(points[:2], 1, exclude=[[0, 1]])
    with pytest.raises(ValueError, match="exclude must lie in"):
        tree.query(points[:1], 1, exclude=[[-1, 3]])


# ---------------------------------------------------------------------------
# relational features


@pytest.mark.parametrize("seed", SEEDS)
def test_hysteresis_equals_its_twin(seed):
    rng = np.random.default_rng(seed)
    for frames in (0, 1, 2, 9, 200):
        for features in (1, 3, 64):
            values = rng.normal(size=(frames, features)).cumsum(axis=0)
            values[rng.random(values.shape) < 0.05] = np.nan
            low = rng.uniform(-2, 1, features)
            high = low + rng.choice([0.0, 0.3, 3.0], features)
            initial = rng.random(features) < 0.5
            got = ms.hysteresis(values, low, high, initial)
            np.testing.assert_array_equal(got, twin.hysteresis(values, low, high, initial))
    line = np.sin(np.arange(100) / 5)
    np.testing.assert_array_equal(ms.hysteresis(line, -0.5, 0.5), twin.hysteresis(line, -0.5, 0.5))
    on = ms.hysteresis([0.0, 1.0, 0.5, 0.0, -1.0, 0.5, 0.5], 0.0, 0.5)
    assert on.tolist() == [False, True, True, True, False, False, False]  # 0.5 and 0.0 sit on the thresholds


def test_pack_bits_and_segments_equal_their_twins(rng):
    for frames, features in ((0, 3), (1, 1), (5, 0), (40, 7), (300, 64)):
        bits = rng.random((frames, features)) < 0.3
        bits[::3] = bits[0] if frames else bits[::3]  # repeated frames make runs
        words = ms.pack_bits(bits)
        np.testing.assert_array_equal(words, twin.pack_bits(bits))
        assert words.dtype == np.uint64
        got = ms.segments(words)
        want = twin.segments(words)
        np.testing.assert_array_equal(got.first, want[0])
        np.testing.assert_array_equal(got.words, want[1])
    top = np.zeros((2, 64), bool)
    top[0, 63] = top[1, 0] = True
    assert ms.pack_bits(top).tolist() == [2**63, 1]


@pytest.mark.parametrize("seed", SEEDS)
def test_feature_index_equals_its_twin(seed):
    rng = np.random.default_rng(seed)
    for takes, frames, values in ((0, 0, 1), (1, 1, 1), (2, 0, 3), (4, 50, 3), (7, 300, 5)):
        data = [rng.integers(0, values, int(rng.integers(0, frames + 1)), dtype=np.uint64) for _ in range(takes)]
        index = ms.FeatureIndex(data)
        keys, offsets, ids = twin.feature_index(data)
        np.testing.assert_array_equal(index.keys, keys)
        np.testing.assert_array_equal(index.offsets, offsets)
        np.testing.assert_array_equal(index.ids, ids)
        for length in (1, 2, 3, 6):
            query = twin.segments(rng.integers(0, values, 4 * length, dtype=np.uint64))[1][:length]
            np.testing.assert_array_equal(index.find(query), twin.feature_find(data, query))


def test_feature_index_finds_a_piece_of_a_take_and_not_across_takes():
    a = np.array([1, 1, 2, 2, 2, 3, 1, 1], np.uint64)
    b = np.array([3, 3, 1, 2], np.uint64)
    index = ms.FeatureIndex([a, np.zeros(0, np.uint64), b, a])
    assert index.find([2, 3]).tolist() == [[0, 2, 6], [3, 2, 6]]
    assert index.find([1, 2]).tolist() == [[0, 0, 5], [2, 2, 4], [3, 0, 5]]
    assert index.find([2, 3, 1]).tolist() == [[0, 2, 8], [3, 2, 8]]  # the last segment runs to the take's end
    assert index.find([1, 3]).tolist() == []  # b ends in 2 and a begins with 1: takes do not join
    assert index.find([9]).shape == (0, 3)
    piece = ms.segments(ms.pack_bits(np.array([[1, 0], [0, 1], [0, 1]], bool))).words
    assert piece.tolist() == [1, 2]
    assert ms.FeatureIndex([]).find([1]).shape == (0, 3)


def test_feature_bad_input():
    with pytest.raises(ValueError, match="at most 64 features"):
        ms.pack_bits(np.zeros((3, 65), bool))
    with pytest.raises(TypeError, match="boolean"):
        ms.pack_bits(np.zeros((3, 2)))
    with pytest.raises(ValueError, match="low must be at most high"):
        ms.hysteresis(np.zeros((4, 2)), [0, 1], [1, 0])
    with pytest.raises(ValueError, match="low must not be NaN"):
        ms.hysteresis(np.zeros(4), math.nan, 1)
    with pytest.raises(ValueError, match="at least one word"):
        ms.FeatureIndex([np.ones(3, np.uint64)]).find([])
    with pytest.raises(ValueError, match="must not be negative"):
        ms.segments(np.array([1, -2]))
    with pytest.raises(TypeError, match="integers"):
        ms.FeatureIndex([np.ones(3)])


@pytest.mark.parametrize(
    ("relation", "message"),
    [
        (ms.Relation("height", 0), "kind must be one of difference, bend, speed, lean, scalar, got 'height'"),
        (ms.Relation("difference", 0, 1, off=1.0, on=0.0), "off must be at most on, got off 1.0 and on 0.0"),
        (ms.Relation("difference", 0, 1, off=math.nan, on=0.0), "off must be at most on"),
        (ms.Relation("difference", 0, 3), "b must be the index of one of the 3 points, got 3"),
        (ms.Relation("difference", 0, -1, 2), "c needs b"),
        (ms.Relation("difference", 0, 1, axis=3), "axis must be 0, 1 or 2, got 3"),
        (ms.Relation("bend", 0, 1), "c must be the index of one of the 3 points, got -1"),
        (ms.Relation("speed", -2), "a must be the index of one of the 3 points, got -2"),
        (ms.Relation("scalar", 1), "a must be the index of one of the 1 scalars, got 1"),
        (ms.Relation("lean", 0, sign=math.inf), "sign must be finite"),
    ],
)
def test_a_relation_that_cannot_be_measured_is_named(relation, message):
    with pytest.raises(ValueError, match=re.escape(f"relation 1 ({relation.kind}): {message}")):
        ms.relations(np.zeros((4, 3, 3)), np.zeros((4, 1)), 10.0, [ms.Relation("lean", 0), relation])


def test_relations_refuse_bad_bodies_and_rates():
    with pytest.raises(ValueError, match="rate must be a finite number"):
        ms.relations(np.zeros((4, 3, 3)), np.zeros((4, 1)), 0.0, [])
    with pytest.raises(ValueError, match="at most 64 relations"):
        ms.relations(np.zeros((4, 3, 3)), np.zeros((4, 1)), 10.0, [ms.Relation("lean", 0)] * 65)
    with pytest.raises(ValueError, match="points"):
        ms.relations(np.zeros((4, 3, 2)), np.zeros((4, 1)), 10.0, [])
    with pytest.raises(ValueError, match="scalars"):
        ms.relations(np.zeros((4, 3, 3)), np.zeros((5, 1)), 10.0, [])


# ---------------------------------------------------------------------------
# layouts: any real dtype and memory layout, computed in float64


def test_dtypes_and_layouts_give_the_float64_results(rng):
    series = np.round(walk(rng, 200, 4) * 10)
    query = series[50:62].copy()
    wide = np.zeros((200, 8))
    wide[:, ::2] = series  # every other column: a strided view
    variants = [series.astype(np.float32), series.astype(np.int32), wide[:, ::2], np.asfortranarray(series)]
    variants.append(np.asfortranarray(variants[0]))
    want = ms.dtw_search(query, series, 3, 2)
    tree = ms.KDTree(series, 8)
    neighbours = tree.query(query, 4)
    for x in variants:
        got = ms.dtw_search(query, x, 3, 2)
        assert got.starts.tolist() == want.starts.tolist() and got.distances.tolist() == want.distances.tolist()
        np.testing.assert_array_equal(ms.KDTree(x, 8).query(query, 4).indices, neighbours.indices)
        np.testing.assert_array_equal(tree.query(x[50:62], 4).indices, neighbours.indices)
    np.testing.assert_array_equal(ms.lb_envelope(series[:, 0], 3).upper, ms.lb_envelope(series[:, :1], 3).upper)
    assert ms.dtw(series[:10, 1], series[5:15, 1], 2) == ms.dtw(series[:10, 1:2], series[5:15, 1:2], 2)


# ---------------------------------------------------------------------------
# the C layer's own checks: what Python validates is checked again, and reported through the one status map


def test_c_refusals_become_value_errors():
    x = np.zeros((4, 2))
    x[1, 1] = np.nan
    d = ffi.new("double *")
    with pytest.raises(ValueError, match=r"^mt_dtw: an argument is outside its documented range \(status -1\)$"):
        check(lib.mt_dtw(c_array(x), 4, c_array(x), 4, 2, 1, math.inf, d), "mt_dtw")
    with pytest.raises(ValueError, match="mt_lb_keogh"):
        check(lib.mt_lb_keogh(c_array(x), c_array(x), c_array(x), 4, 2, math.nan, d), "mt_lb_keogh")
    with pytest.raises(ValueError, match="mt_lb_envelope"):
        check(lib.mt_lb_envelope(c_array(x), 4, 2, 1, c_array(np.empty((4, 2))), c_array(np.empty((4, 2)))),
              "mt_lb_envelope")  # fmt: skip

    series = np.zeros((10, 1))
    out = np.empty(2, dtype=np.uintp)
    found = ffi.new("size_t *")
    unsorted, sorted_ = np.array([3, 2], dtype=np.uintp), np.arange(2, dtype=np.uintp)
    for dtype, starts, error in ((lib.MT_FLOAT64, unsorted, ValueError), (7, sorted_, TypeError)):
        status = lib.mt_dtw_search(
            c_array(series), 2, dtype, c_array(series), 10, 1, 1, c_array(starts, "size_t[]"), 2, 1,
            c_array(np.empty(2)), c_array(out, "size_t[]"), c_array(out, "size_t[]"), c_array(np.empty(2)), found,
            ffi.NULL,
        )  # fmt: skip
        with pytest.raises(error, match="mt_dtw_search"):
            check(status, "mt_dtw_search")

    words = np.zeros(3, np.uint64)
    with pytest.raises(ValueError, match="mt_pack_bits"):
        check(lib.mt_pack_bits(c_array(np.zeros(3 * 65, np.uint8), "unsigned char[]"), 3, 65,
                               c_array(words, "uint64_t[]")), "mt_pack_bits")  # fmt: skip
    table = ffi.new("struct mt_relation[]", [{"kind": lib.MT_RELATION_BEND, "a": 0, "b": 1, "c": 5}])
    with pytest.raises(ValueError, match="mt_relations"):  # c past the 3 points
        check(lib.mt_relations(c_array(np.zeros(9)), 1, 3, ffi.NULL, 0, 10.0, table, 1, ffi.NULL,
                               c_array(words, "uint64_t[]")), "mt_relations")  # fmt: skip
    depth = ffi.new("size_t *")
    with pytest.raises(ValueError, match="mt_kdtree_depth"):
        check(lib.mt_kdtree_depth(10, 0, depth), "mt_kdtree_depth")


def test_a_corrupt_tree_is_refused_not_followed(rng):
    tree = ms.KDTree(walk(rng, 100, 3), 4)
    tree.split_dim[0] = 7  # beyond the 3 dimensions
    with pytest.raises(ValueError, match="mt_kdtree_query"):
        tree.query(np.zeros(3), 2)
    tree = ms.KDTree(walk(rng, 100, 3), 4)
    tree.index[50] = 100  # beyond the rows
    with pytest.raises(ValueError, match="mt_kdtree_query"):
        tree.query(np.zeros((5, 3)) + tree.rows[49], 100)
    tree = ms.KDTree(walk(rng, 100, 3), 4)
    tree._tree.depth = 2  # not the depth of 100 rows in leaves of 4
    with pytest.raises(ValueError, match="mt_kdtree_query"):
        tree.query(np.zeros(3), 2)
    tree = ms.KDTree(walk(rng, 100, 3), 4)
    tree._tree.dtype = 7  # not an mt_dtype
    with pytest.raises(TypeError, match="mt_kdtree_query"):
        tree.query(np.zeros(3), 2)
