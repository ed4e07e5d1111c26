"""Slow twins of the search-by-example kernels (mtcore.search), written from their definitions:
windows sliced and reduced by numpy, the DTW recurrence cell by cell, every distance computed
and sorted for the searches.  Also the argument tuples that test_twins and test_concurrent
feed the kernels and their twins."""

import math

import numpy as np


def rows(x):
    """x as float64 (frames, dims): a 1-D sequence is one dimension."""
    a = np.asarray(x, float)
    return a[:, None] if a.ndim == 1 else a


# --- dynamic time warping -------------------------------------------------------------------


def lb_envelope(x, radius):
    """Maximum and minimum of each window x[t - radius : t + radius + 1], cut at the ends."""
    x = rows(x)
    n = len(x)
    upper, lower = np.empty_like(x), np.empty_like(x)
    for t in range(n):
        window = x[max(0, t - radius) : t + radius + 1]
        upper[t], lower[t] = window.max(axis=0), window.min(axis=0)
    return upper, lower


def lb_keogh(candidate, upper, lower, threshold=math.inf):
    """Per frame the squared distance to [lower, upper]; summed until the sum passes threshold."""
    c = rows(candidate)
    terms = (np.maximum(c - upper, 0) ** 2 + np.maximum(lower - c, 0) ** 2).sum(axis=1)
    total = 0.0
    for term in terms:
        total += term
        if total > threshold:
            break
    return total


def dtw(a, b, radius=None, threshold=math.inf):
    """The recurrence D(i, j) = |a_i - b_j|^2 + min(D(i-1, j), D(i, j-1), D(i-1, j-1)) over the
    whole matrix, cells outside |i - j| <= radius at inf; inf once a row's every cell is above threshold."""
    a = rows(a)
    b = rows(b)
    m, n = len(a), len(b)
    if m == 0 or n == 0:
        return 0.0 if m == n else math.inf
    r = max(m, n) if radius is None else radius
    cost = ((a[:, None, :] - b[None, :, :]) ** 2).sum(axis=2)
    D = np.full((m + 1, n + 1), math.inf)
    D[0, 0] = 0.0
    for i in range(1, m + 1):
        for j in range(1, n + 1):
            if abs(i - j) <= r:
                D[i, j] = cost[i - 1, j - 1] + min(D[i - 1, j], D[i, j - 1], D[i - 1, j - 1])
        if D[i, 1:].min() > threshold:
            return math.inf
    return float(D[m, n])


def dtw_search(query, series, k=1, radius=None, starts=None):
    """DTW at every candidate window, sorted by (distance, start): the first k starts and distances."""
    query = rows(query)
    series = rows(series)
    m = len(query)
    if starts is None:
        starts = range(max(len(series) - m + 1, 0))
    found = sorted((dtw(query, series[s : s + m], radius), int(s)) for s in starts)[:k]
    return np.array([s for _, s in found], dtype=np.intp), np.array([d for d, _ in found])


# --- nearest neighbours ---------------------------------------------------------------------


def knn(points, queries, k=1, exclude=None):
    """Every squared distance, excluded rows at inf, sorted by (distance, row): the first min(k, n)."""
    points = np.asarray(points, float)
    queries = np.asarray(queries, float).reshape(-1, points.shape[1])
    n = len(points)
    width = min(k, n)
    indices = np.full((len(queries), width), -1, dtype=np.intp)
    distances = np.full((len(queries), width), math.inf)
    for i, q in enumerate(queries):
        d = ((points - q) ** 2).sum(axis=1)
        rows = np.arange(n)
        if exclude is not None:
            keep = (rows < exclude[i][0]) | (rows >= exclude[i][1])
            d, rows = d[keep], rows[keep]
        order = np.lexsort((rows, d))[:width]
        indices[i, : len(order)] = rows[order]
        distances[i, : len(order)] = d[order]
    return indices, distances


# --- relational features ----------------------------------------------------------------------


def hysteresis(values, low, high, initial=False):
    """Frame by frame: on above high, off below low, else (NaN too) as the frame before."""
    v = np.asarray(values, float)
    one = v.ndim == 1
    v = rows(v)
    features = v.shape[1]
    low, high = np.broadcast_to(low, features), np.broadcast_to(high, features)
    state = np.broadcast_to(np.asarray(initial, bool), features).copy()
    out = np.zeros(v.shape, bool)
    for t in range(len(v)):
        for f in range(features):
            if v[t, f] > high[f]:
                state[f] = True
            elif v[t, f] < low[f]:
                state[f] = False
            out[t, f] = state[f]
    return out[:, 0] if one else out


def relations(points, scalars, rate, table):
    """Each relation measured frame by frame from its definition, then its hysteresis and the words."""
    p, sc = np.asarray(points, float), np.asarray(scalars, float)
    n = len(p)
    values = np.zeros((n, len(table)))
    for t in range(n):
        for i, r in enumerate(table):
            values[t, i] = _measure(r, p, sc, rate, t)
    on = hysteresis(values, [r.off for r in table], [r.on for r in table]) if table else np.zeros((n, 0), bool)
    return pack_bits(on), values


def _measure(r, p, scalars, rate, t):
    def point(i, frame=t):
        return p[frame, i]

    if r.kind == "difference":
        base = 0.0 if r.b < 0 else point(r.b)[r.axis] if r.c < 0 else np.minimum(point(r.b)[r.axis], point(r.c)[r.axis])
        v = point(r.a)[r.axis] - base
    elif r.kind == "bend":
        u, w = point(r.a) - point(r.b), point(r.c) - point(r.b)
        cos = np.dot(u, w) / np.maximum(math.sqrt(np.dot(u, u)) * math.sqrt(np.dot(w, w)), 1e-12)
        v = 180.0 - math.degrees(math.acos(np.clip(cos, -1.0, 1.0))) if not math.isnan(cos) else math.nan
    elif r.kind == "speed":
        if len(p) < 2:
            v = 0.0
        else:
            after, before = min(t + 1, len(p) - 1), max(t - 1, 0)
            v = math.sqrt(np.sum(((point(r.a, after) - point(r.a, before)) / (after - before)) ** 2)) * rate
    elif r.kind == "lean":
        x, y, z = point(r.a)
        v = math.degrees(math.atan2(math.hypot(x, z), y))
    else:
        v = scalars[t, r.a]
    return r.sign * (abs(v) if r.absolute else v)


def relation_cases(rng):
    from mtcore.search import Relation

    out = []
    for frames in (0, 1, 2, 3, 40):
        points = rng.normal(size=(frames, 6, 3)).cumsum(axis=0) * 0.3
        scalars = rng.normal(size=(frames, 2))
        if frames > 2:
            points[1, 4] = math.nan  # a gap holds every relation of the point as it was
            scalars[2, 1] = math.nan
        table = []
        for _ in range(12):
            kind = str(rng.choice(["difference", "bend", "speed", "lean", "scalar"]))
            a, b, c = (int(i) for i in rng.choice(6, 3, replace=False))
            if kind == "difference":
                b, c = (b, c) if rng.random() < 0.4 else (b, -1) if rng.random() < 0.5 else (-1, -1)
            elif kind == "scalar":
                a = int(rng.integers(2))
            off = float(rng.normal()) * (30.0 if kind in ("bend", "lean") else 0.5) + (60.0 if kind == "bend" else 0.0)
            table.append(
                Relation(kind, a, b, c, int(rng.integers(3)), float(rng.choice([1.0, -1.0])), bool(rng.random() < 0.3),
                         off, off + float(rng.choice([0.0, 0.2, 5.0])))
            )  # fmt: skip
        out.append((points, scalars, float(rng.choice([10.0, 120.0])), table))
    return out + [(np.zeros((3, 1, 3)), np.zeros((3, 0)), 30.0, [])]


def body_relations(b):
    """Müller's facts of a Body (motiontheater.databases.features) written out with numpy, one by
    one as RELATIONS names them: what the table must mean, as booleans (frames, 25)."""
    at = b.at
    values, low, high = [], [], []

    def fact(value, off, on):
        values.append(value)
        low.append(off)
        high.append(on)

    def angle(a, b_, c):
        u, v = a - b_, c - b_
        cos = np.sum(u * v, -1) / np.maximum(np.linalg.norm(u, axis=-1) * np.linalg.norm(v, axis=-1), 1e-12)
        return np.degrees(np.arccos(np.clip(cos, -1, 1)))

    def speed(name):
        p = at(name)
        return np.linalg.norm(np.gradient(p, axis=0), axis=1) * b.rate if len(p) > 1 else np.zeros(len(p))

    fact(at("right_ankle")[:, 2] - at("left_ankle")[:, 2], 0.1, 0.2)
    fact(at("left_ankle")[:, 2] - at("right_ankle")[:, 2], 0.1, 0.2)
    fact(at("right_ankle")[:, 1] - at("left_ankle")[:, 1], 0.1, 0.2)
    fact(at("left_ankle")[:, 1] - at("right_ankle")[:, 1], 0.1, 0.2)
    for side in ("right", "left"):
        fact(180 - angle(at(f"{side}_hip"), at(f"{side}_knee"), at(f"{side}_ankle")), 40.0, 60.0)
    for side in ("right", "left"):
        fact(at(f"{side}_wrist")[:, 1] - at("head")[:, 1], -0.05, 0.05)
    for side in ("right", "left"):
        fact(at(f"{side}_wrist")[:, 2], 0.3, 0.45)
    for side, sign in (("right", -1.0), ("left", 1.0)):
        fact(sign * (at(f"{side}_wrist")[:, 0] - at(f"{side}_shoulder")[:, 0]), 0.35, 0.5)
    for side in ("right", "left"):
        knees = np.minimum(at("right_knee")[:, 1], at("left_knee")[:, 1])
        fact(knees - at(f"{side}_wrist")[:, 1], -0.05, 0.05)
    for side in ("right", "left"):
        fact(180 - angle(at(f"{side}_shoulder"), at(f"{side}_elbow"), at(f"{side}_wrist")), 50.0, 70.0)
    for name in ("right_wrist", "left_wrist", "right_ankle", "left_ankle"):
        fact(speed(name), 1.5, 2.0)
    fact(np.abs(at("right_ankle")[:, 0] - at("left_ankle")[:, 0]), 0.45, 0.6)
    fact(-b.height, -0.75, -0.65)
    torso = at("neck")
    fact(np.degrees(np.arctan2(np.linalg.norm(torso[:, [0, 2]], axis=1), torso[:, 1])), 30.0, 45.0)
    fact(b.speed, 0.6, 0.9)
    fact(np.abs(b.turning), 60.0, 90.0)
    return hysteresis(np.stack(values, axis=1), np.array(low), np.array(high))


def pack_bits(bits):
    """Python integers: the sum of 2^f over the set bits f of each frame."""
    bits = np.asarray(bits, bool)
    return np.array([sum(1 << f for f in np.flatnonzero(row)) for row in bits], dtype=np.uint64)


def segments(words):
    """A new segment wherever the word differs from the frame before."""
    first, values = [], []
    for t, w in enumerate(np.asarray(words, np.uint64)):
        if t == 0 or w != values[-1]:
            first.append(t)
            values.append(w)
    return np.array(first, dtype=np.intp), np.array(values, dtype=np.uint64)


def feature_index(takes):
    """Per take its segments; the distinct words ascending, each with the ids of the segments that hold it."""
    cut = [segments(t) for t in takes]
    words = np.concatenate([w for _, w in cut]) if cut else np.empty(0, np.uint64)
    keys = np.unique(words)
    lists = [np.flatnonzero(words == key) for key in keys]
    offsets = np.concatenate([[0], np.cumsum([len(ids) for ids in lists])]).astype(np.intp)
    ids = np.concatenate(lists).astype(np.intp) if lists else np.empty(0, np.intp)
    return keys, offsets, ids


def feature_find(takes, query):
    """Every take and every segment s of it with the query's words at s, s + 1, ...: (take, first, stop) frames."""
    hits = []
    for t, words in enumerate(takes):
        first, values = segments(words)
        for s in range(len(values) - len(query) + 1):
            if all(values[s + j] == query[j] for j in range(len(query))):
                end = s + len(query)
                hits.append((t, first[s], first[end] if end < len(values) else len(words)))
    return np.array(hits, dtype=np.intp).reshape(-1, 3)


# --- cases ----------------------------------------------------------------------------------


def walk(rng, frames, dims, scale=1.0):
    """A smooth random walk, as motion is; integers now and then, where distances tie."""
    x = rng.normal(size=(frames, dims)).cumsum(axis=0) * scale
    return np.round(x) if rng.random() < 0.3 else x


def envelope_cases(rng):
    return [
        (walk(rng, frames, dims), radius)
        for frames in (0, 1, 2, 5, 8, 33)
        for dims in (1, 3)
        for radius in (0, 1, 2, 7, 40)
    ]


def keogh_cases(rng):
    out = []
    for frames, dims in ((0, 2), (1, 1), (6, 3), (31, 2), (64, 5)):
        query, candidate = walk(rng, frames, dims), walk(rng, frames, dims)
        for radius in (0, 3):
            upper, lower = lb_envelope(query, radius)
            out += [(candidate, upper, lower, math.inf), (candidate, upper, lower, float(rng.uniform(0, 40)))]
    return out


def dtw_cases(rng):
    out = []
    for m, n, dims in ((0, 0, 2), (0, 3, 2), (1, 1, 1), (1, 4, 3), (5, 5, 2), (7, 4, 1), (12, 15, 3), (20, 20, 4)):
        a, b = walk(rng, m, dims), walk(rng, n, dims)
        for radius in (0, 1, 3, None):
            out.append((a, b, radius, math.inf))
        out.append((a, b, 2, float(rng.uniform(0, 50))))
    return out


def dtw_search_cases(rng):
    out = []
    for m, n, dims in ((0, 5, 2), (1, 1, 1), (4, 30, 2), (9, 80, 3), (16, 120, 2)):
        series = walk(rng, n, dims)
        query = series[n // 3 : n // 3 + m] + rng.normal(0, 0.3, (m, dims)) if m <= n else walk(rng, m, dims)
        for k, radius in ((1, 0), (3, 2), (5, None), (200, 1)):
            out.append((query, series, k, radius, None))
        picked = np.flatnonzero(rng.random(max(n - m + 1, 0)) < 0.4)
        out.append((query, series, 2, 2, picked))
    integers = np.round(walk(rng, 60, 2))  # exact sums: ties that only the start breaks
    out.append((integers[10:16], np.concatenate([integers, integers[::-1], integers]), 4, 1, None))
    return out


def knn_cases(rng):
    out = []
    for n, dims, leaf in ((0, 3, 4), (1, 1, 1), (2, 2, 1), (7, 3, 2), (50, 4, 3), (300, 6, 8), (257, 30, 16)):
        points = walk(rng, n, dims)
        queries = np.concatenate([points[: min(n, 5)], walk(rng, 4, dims)])
        for k in (1, 3, n + 2):
            out.append((points, leaf, queries, k, None))
        if n:
            lo = rng.integers(0, n, len(queries))
            out.append((points, leaf, queries, 2, np.stack([lo, lo + rng.integers(0, 5, len(queries))], axis=1)))
    grid = np.array([[x, y] for x in range(6) for y in range(6)], float)  # many equal distances
    out.append((np.concatenate([grid, grid]), 3, grid[::5] + 0.5, 7, None))
    return out


def hysteresis_cases(rng):
    out = []
    for frames, features in ((0, 2), (1, 1), (9, 3), (100, 4)):
        values = rng.normal(size=(frames, features)).cumsum(axis=0)
        values[rng.random(values.shape) < 0.05] = math.nan
        low = rng.uniform(-2, 0, features)
        high = low + rng.choice([0.0, 0.5, 2.0], features)
        out += [(values, low, high, False), (values, low, high, rng.random(features) < 0.5)]
    return out + [(rng.normal(size=30), -0.2, 0.3, True)]


def pack_cases(rng):
    return [(rng.random((frames, features)) < 0.4,) for frames, features in ((0, 5), (1, 1), (7, 0), (20, 33), (9, 64))]


def segment_cases(rng):
    return [
        (rng.integers(0, values, frames, dtype=np.uint64),) for frames, values in ((0, 2), (1, 2), (30, 3), (200, 2))
    ] + [(np.array([2**64 - 1, 2**64 - 1, 0, 2**63], dtype=np.uint64),)]


def feature_takes(rng, takes, frames, values):
    return [rng.integers(0, values, int(rng.integers(0, frames + 1)), dtype=np.uint64) for _ in range(takes)]


def feature_index_cases(rng):
    return [
        (feature_takes(rng, takes, frames, values),)
        for takes, frames, values in ((0, 0, 1), (1, 0, 2), (3, 20, 3), (5, 80, 4))
    ]


def feature_find_cases(rng):
    out = []
    for takes, frames, values in ((1, 1, 2), (3, 20, 3), (6, 120, 3), (4, 60, 2)):
        data = feature_takes(rng, takes, frames, values)
        for length in (1, 2, 4):
            query = segments(rng.integers(0, values, 3 * length, dtype=np.uint64))[1][:length]
            out.append((data, query))
        longest = max(data, key=len)
        if len(longest) > 10:
            out.append((data, segments(longest[3:10])[1]))  # a piece of a take: found there at least
    return out
