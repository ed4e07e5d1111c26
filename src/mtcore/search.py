"""Search by example, in C: motions found by a piece of motion (issue 27).

Three ways, each exact, each with the slow, obvious answer it must give spelled out:

- dynamic time warping (:func:`dtw`) in a Sakoe-Chiba band, its LB_Keogh lower bound
  (:func:`lb_envelope`, :func:`lb_keogh`) and :func:`dtw_search`, the k windows of a long
  series nearest a query, which warps only the windows whose bound can still win;
- :class:`KDTree`: the k nearest rows of a matrix (frames of poses, feature vectors)
  to each query row, with rows excluded per query (a frame and its neighbours);
- relational features (Müller, Röder and Clausen, SIGGRAPH 2005): a body's
  :func:`relations` (each a :class:`Relation` of its points, in one pass), thresholds with
  :func:`hysteresis`, bits packed into one word per frame (:func:`pack_bits`), runs of equal
  words (:func:`segments`) and :class:`FeatureIndex`, an inverted index of many takes'
  segments that finds where a query's sequence of words occurs.

Sequences and point sets are ``(frames, dims)`` arrays of any real dtype (a 1-D array is one
dimension), computed in float64; inputs are never modified.  What a search stores (the series of
:func:`dtw_search`, the rows of a :class:`KDTree`) stays float32 where it is given so, in half the
memory: its values are read as the doubles they are, so that the results are exactly those of
float64 arrays of the same values.  Every value searched must be finite: a NaN or an infinity
is refused with a ValueError naming its place (a NaN orders nothing; fill gaps first,
:func:`mtcore.signal.fill_gaps`).  Distances are *squared* Euclidean, and a DTW distance is
the sum of the squared distances of the frames its path pairs: no square root is taken, so
that bounds and distances compare exactly.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from . import _checks
from ._cdata import c_array
from ._mtcore import ffi, lib
from ._parallel import even_bounds, run_ranges, thread_count
from ._status import check

__all__ = [
    "DTWHits",
    "Envelope",
    "FeatureIndex",
    "KDTree",
    "Neighbours",
    "Relation",
    "Relations",
    "Segments",
    "dtw",
    "dtw_search",
    "hysteresis",
    "lb_envelope",
    "lb_keogh",
    "pack_bits",
    "relations",
    "segments",
]

# Query rows x tree rows below which a second thread costs more than it saves.
_PARALLEL_MIN_WORK = 1 << 22


def _sequence(x: ArrayLike, name: str, dims: int | None = None, keep: tuple = ()) -> np.ndarray:
    """``x`` as a C-contiguous float64 (frames, dims) array of finite values (1-D: one dimension),
    or of its own dtype where that is one of ``keep``."""
    a = np.asarray(x) if x is not None else None
    if a is not None and a.ndim == 1:
        a = a[:, None]
    array = _checks.real(a, name, (None, "dims" if dims is None else dims), keep)
    _finite(array, name)
    return array


# What a search stores (a series, a tree's rows) stays float32 where it is given so.
_STORED = (np.dtype(np.float32),)


def _dtype(stored: np.ndarray) -> int:
    """The mt_dtype of an array :func:`_sequence` gave with ``keep=_STORED``."""
    return lib.MT_FLOAT32 if stored.dtype == np.float32 else lib.MT_FLOAT64


def _finite(a: np.ndarray, name: str) -> None:
    bad = ~np.isfinite(a)
    if bad.any():
        at = tuple(int(i) for i in np.argwhere(bad)[0])
        raise ValueError(
            f"{name} must be finite (a NaN orders nothing: fill or drop it first), got {a[at]} at {name}[{at[0]}, {at[1]}]"
        )


def _radius(radius: int | None, longest: int) -> int:
    """The band's radius: None is no band (the longest sequence's length)."""
    return longest if radius is None else _checks.integer(radius, "radius", 0)


def _threshold(threshold: float) -> float:
    value = float(threshold)
    if math.isnan(value):
        raise ValueError("threshold must be a number or inf, got nan")
    return value


# ---------------------------------------------------------------------------
# dynamic time warping


class Envelope(NamedTuple):
    """The LB_Keogh envelope of a sequence: ``upper`` and ``lower`` (frames, dims), its running
    maximum and minimum over frames t - radius .. t + radius."""

    upper: np.ndarray
    lower: np.ndarray


def lb_envelope(x: ArrayLike, radius: int) -> Envelope:
    """The envelope of ``x`` (frames, dims) for a band of ``radius`` frames (0: ``x`` itself),
    dimension by dimension, the window cut at the ends of the sequence; O(frames) for any radius."""
    a = _sequence(x, "x")
    r = _checks.integer(radius, "radius", 0)
    upper, lower = np.empty_like(a), np.empty_like(a)
    check(lib.mt_lb_envelope(c_array(a), len(a), a.shape[1], r, c_array(upper), c_array(lower)), "mt_lb_envelope")
    return Envelope(upper, lower)


def lb_keogh(candidate: ArrayLike, envelope: tuple[ArrayLike, ArrayLike], threshold: float = math.inf) -> float:
    """LB_Keogh: the squared distance of ``candidate`` (frames, dims) to a query's ``envelope``
    (:func:`lb_envelope`, the query as long as the candidate), frame by frame; never above
    :func:`dtw` of the query and candidate in the same band.  The sum stops once above
    ``threshold``, and that partial sum (above it, still a lower bound) is returned."""
    c = _sequence(candidate, "candidate")
    upper = _sequence(envelope[0], "envelope.upper", c.shape[1])
    lower = _sequence(envelope[1], "envelope.lower", c.shape[1])
    if upper.shape != c.shape or lower.shape != c.shape:
        raise ValueError(f"the envelope must have the candidate's shape {c.shape}, got {upper.shape} and {lower.shape}")
    bound = ffi.new("double *")
    status = lib.mt_lb_keogh(
        c_array(c), c_array(upper), c_array(lower), len(c), c.shape[1], _threshold(threshold), bound
    )
    check(status, "mt_lb_keogh")
    return float(bound[0])


def dtw(a: ArrayLike, b: ArrayLike, radius: int | None = None, threshold: float = math.inf) -> float:
    """The DTW distance of ``a`` (m, dims) and ``b`` (n, dims): the least sum of squared distances
    |a_i - b_j|^2 over a path from (0, 0) to (m-1, n-1) of steps (1, 0), (0, 1) and (1, 1) with
    |i - j| <= ``radius`` (None: no band; 0 for m = n: the squared Euclidean distance).

    inf where no path fits the band (|m - n| > radius, or one sequence empty; two empty ones
    are at 0), and where every cell of a row of the cost matrix exceeds ``threshold`` (the
    distance then does too: an early abandon).
    """
    x = _sequence(a, "a")
    y = _sequence(b, "b", x.shape[1])
    distance = ffi.new("double *")
    r = _radius(radius, max(len(x), len(y)))
    status = lib.mt_dtw(c_array(x), len(x), c_array(y), len(y), x.shape[1], r, _threshold(threshold), distance)
    check(status, "mt_dtw")
    return float(distance[0])


class DTWHits(NamedTuple):
    """The result of :func:`dtw_search`: ``starts`` and ``distances`` of the windows found,
    nearest first (a tie to the lower start); ``bounds``, each candidate's LB_Keogh (or, where
    it passed the k-th distance of the k windows warped first, the partial sum that did: a
    lower bound of its distance all the same); and how many candidates were warped to the
    end, ``abandoned`` on the way, and ``pruned`` (never warped)."""

    starts: np.ndarray
    distances: np.ndarray
    bounds: np.ndarray
    warped: int
    abandoned: int
    pruned: int


def dtw_search(
    query: ArrayLike, series: ArrayLike, k: int = 1, radius: int | None = None, starts: ArrayLike | None = None
) -> DTWHits:
    """The ``k`` windows of ``series`` (n, dims) nearest to ``query`` (m, dims) by :func:`dtw`.

    The candidates are the windows of m frames beginning at ``starts`` (strictly increasing,
    each at most n - m; None: every one, 0 .. n - m).  The result is exactly what warping every
    candidate and sorting by (distance, start) gives, the first min(k, candidates) of them;
    the search only skips windows that cannot be among them (their LB_Keogh is above the k-th
    best distance found so far), and abandons warps that pass it.  Overlapping windows are not
    merged: the neighbours of a good window are usually good too.
    """
    q = _sequence(query, "query")
    s = _sequence(series, "series", q.shape[1], _STORED)
    k = _checks.integer(k, "k", 1)
    m, n = len(q), len(s)
    r = _radius(radius, m)
    if starts is None:
        first = np.arange(max(n - m + 1, 0), dtype=np.uintp)
    else:
        first = np.asarray(starts)
        if first.size and m > n:
            raise ValueError(f"starts: no window of the query's {m} frames fits in the series' {n}")
        first = _checks.integers(first, "starts", (None,), 0, n - m + 1, np.uintp)
        if len(first) > 1 and not (first[1:] > first[:-1]).all():
            i = int(np.flatnonzero(first[1:] <= first[:-1])[0]) + 1
            raise ValueError(f"starts must be strictly increasing, got starts[{i}] = {first[i]} after {first[i - 1]}")
    count = len(first)
    hits = np.empty(min(k, count), dtype=np.uintp)
    distances = np.empty(min(k, count))
    bounds = np.empty(count)
    order = np.empty(count, dtype=np.uintp)
    found = ffi.new("size_t *")
    stats: Any = ffi.new("struct mt_dtw_stats *")
    status = lib.mt_dtw_search(
        c_array(q), m, _dtype(s), c_array(s, "char[]"), n, q.shape[1], r, c_array(first, "size_t[]"), count, min(k, max(count, 1)),
        c_array(bounds), c_array(order, "size_t[]"), c_array(hits, "size_t[]"), c_array(distances), found, stats,
    )  # fmt: skip
    check(status, "mt_dtw_search")
    return DTWHits(
        hits[: found[0]].astype(np.intp), distances[: found[0]], bounds, stats.warped, stats.abandoned, stats.pruned
    )


# ---------------------------------------------------------------------------
# nearest neighbours


class Neighbours(NamedTuple):
    """The result of :meth:`KDTree.query`: ``indices`` of the rows found and their squared
    ``distances``, nearest first (a tie to the lower row); -1 and inf past the rows there were."""

    indices: np.ndarray
    distances: np.ndarray


class KDTree:
    """A k-d tree over the rows of ``points`` (n, dims) for exact k-nearest-neighbour queries
    under squared Euclidean distance.

    Leaves hold at most ``leaf_size`` rows; nodes split their rows at the median of the
    dimension they spread most in.  The tree keeps a copy of the points, in the order of its
    leaves (``rows``; row i is row ``index[i]`` of ``points``), float32 where the points are.
    Queries are exact, ties included: what sorting every row's distance gives.
    """

    def __init__(self, points: ArrayLike, leaf_size: int = 64) -> None:
        a = np.asarray(points) if points is not None else None
        source = _checks.real(a, "points", (None, "dims"), _STORED)
        _finite(source, "points")
        n, dims = source.shape
        if dims == 0:
            raise ValueError("points must have at least one column (dimension), got shape (n, 0)")
        self.leaf_size = _checks.integer(leaf_size, "leaf_size", 1)
        depth = ffi.new("size_t *")
        check(lib.mt_kdtree_depth(n, self.leaf_size, depth), "mt_kdtree_depth")
        self.depth = int(depth[0])
        self.index = np.empty(n, dtype=np.uintp)
        self.rows = np.empty_like(source)
        self.split_dim = np.empty((1 << self.depth) - 1, dtype=np.uintp)
        self.split_value = np.empty((1 << self.depth) - 1)
        # the struct points into the arrays; these cdata views keep them alive with it
        self._views = [
            c_array(self.index, "size_t[]"),
            c_array(self.rows, "char[]"),
            c_array(self.split_dim, "size_t[]"),
            c_array(self.split_value),
        ]
        tree: Any = ffi.new("struct mt_kdtree *")
        tree.index, tree.rows, tree.split_dim, tree.split_value = self._views
        tree.n, tree.dims, tree.leaf_size, tree.depth, tree.dtype = n, dims, self.leaf_size, self.depth, _dtype(source)
        tree.points = c_array(source, "char[]")  # read by the build only
        check(lib.mt_kdtree_build(tree), "mt_kdtree_build")
        tree.points = ffi.NULL
        self._tree = tree

    @property
    def n(self) -> int:
        """Rows in the tree."""
        return int(self.rows.shape[0])

    @property
    def dims(self) -> int:
        """Columns of each row."""
        return int(self.rows.shape[1])

    def query(
        self, queries: ArrayLike, k: int = 1, *, exclude: ArrayLike | None = None, workers: int | None = None
    ) -> Neighbours:
        """The ``k`` nearest rows to each query row: ``queries`` (count, dims), or one row (dims,)
        for results of shape (k,).  Results are (count, min(k, n)).

        ``exclude`` (count, 2), or (2,) with one query: query i ignores rows exclude[i, 0] ..
        exclude[i, 1] - 1 (for a query that is row j of the tree, ``(j - w, j + w + 1)`` keeps
        it from finding itself and its w neighbours on each side); where fewer rows remain than
        asked for, the slots left are -1 and inf.  Queries are split over ``workers`` threads
        (None: every core for large batches; the result does not depend on it).
        """
        q = np.asarray(queries) if queries is not None else None
        single = q is not None and q.ndim == 1
        rows = _checks.real(q[None] if single and q is not None else q, "queries", (None, self.dims))
        _finite(rows, "queries")
        k = _checks.integer(k, "k", 1)
        count, width = len(rows), min(k, self.n)
        spans = None
        if exclude is not None:
            e = np.asarray(exclude)
            spans = _checks.integers(e[None] if single and e.ndim == 1 else e, "exclude", (count, 2), 0, 2**63)
            spans = np.minimum(spans, self.n).astype(np.uintp)
        indices = np.empty((count, width), dtype=np.uintp)
        distances = np.empty((count, width))
        found = np.empty(count, dtype=np.uintp)
        if count and width:
            tree = self._tree

            def call(begin: int, end: int) -> int:
                return lib.mt_kdtree_query(
                    tree, c_array(rows[begin:end]), end - begin, width,
                    c_array(None if spans is None else spans[begin:end], "size_t[]"),
                    c_array(indices[begin:end], "size_t[]"), c_array(distances[begin:end]),
                    c_array(found[begin:end], "size_t[]"),
                )  # fmt: skip

            threads = thread_count(workers, count * self.n >= _PARALLEL_MIN_WORK)
            run_ranges(call, even_bounds(count, threads), "mt_kdtree_query")
        result = np.where(distances < math.inf, indices, -1).astype(np.intp) if width else indices.astype(np.intp)
        if single:
            return Neighbours(result[0], distances[0])
        return Neighbours(result, distances)


# ---------------------------------------------------------------------------
# relational features


RELATION_KINDS = ("difference", "bend", "speed", "lean", "scalar")
"""What a :class:`Relation` measures, by its points a, b, c (indices into the body's points; -1
none) and, for "scalar", a the index of a scalar: "difference", point a's coordinate ``axis``
minus the lower of b's and c's (b's alone where c is -1; 0 where b is too); "bend", 180 minus
the angle at b between a and c, in degrees; "speed", how fast a moves (central differences,
one-sided at the ends), per second; "lean", the angle of a from the y axis, in degrees;
"scalar", the body's scalar a."""


class Relation(NamedTuple):
    """One relational feature: its value, what ``kind`` measures times ``sign`` (of its magnitude
    where ``absolute``), turns it on above ``on`` and off below ``off``."""

    kind: str
    a: int
    b: int = -1
    c: int = -1
    axis: int = 0
    sign: float = 1.0
    absolute: bool = False
    off: float = 0.0
    on: float = 0.0


class Relations(NamedTuple):
    """A body's relations: ``words`` (frames,) uint64, bit r the state of relation r; ``values``
    (frames, relations) what each measured."""

    words: np.ndarray
    values: np.ndarray


def relations(points: ArrayLike, scalars: ArrayLike, rate: float, table: Sequence[Relation]) -> Relations:
    """The relations of ``table`` (at most 64) over a body's ``points`` (frames, points, 3) and
    ``scalars`` (frames, scalars) at ``rate`` frames a second, each with hysteresis as
    :func:`hysteresis` gives it from off, packed as :func:`pack_bits` packs them: one pass over
    the frames in C."""
    p = _checks.real(points, "points", (None, "points", 3))
    v = _checks.real(scalars, "scalars", (len(p), "scalars"))
    if not (isinstance(rate, (int, float)) and math.isfinite(rate) and rate > 0):
        raise ValueError(f"rate must be a finite number of frames a second above 0, got {rate!r}")
    if len(table) > 64:
        raise ValueError(f"at most 64 relations fit one uint64 word a frame, got {len(table)}")
    c_table: Any = ffi.new("struct mt_relation[]", max(len(table), 1))
    for i, r in enumerate(table):
        problem = _relation_problem(r, p.shape[1], v.shape[1])
        if problem:
            raise ValueError(f"relation {i} ({r.kind}): {problem}")
        c = c_table[i]
        c.kind, c.a, c.b, c.c, c.axis = RELATION_KINDS.index(r.kind), r.a, r.b, r.c, r.axis
        c.absolute, c.sign, c.off, c.on = bool(r.absolute), r.sign, r.off, r.on
    words = np.empty(len(p), dtype=np.uint64)
    values = np.empty((len(p), len(table)))
    status = lib.mt_relations(
        c_array(p), len(p), p.shape[1], c_array(v), v.shape[1], float(rate), c_table, len(table), c_array(values),
        c_array(words, "uint64_t[]"),
    )  # fmt: skip
    check(status, "mt_relations")
    return Relations(words, values)


def _relation_problem(r: Relation, points: int, scalars: int) -> str:
    """What makes ``r`` unmeasurable on a body of so many points and scalars, or ""."""
    if r.kind not in RELATION_KINDS:
        return f"kind must be one of {', '.join(RELATION_KINDS)}, got {r.kind!r}"
    if not r.off <= r.on:
        return f"off must be at most on, got off {r.off} and on {r.on}"
    if not math.isfinite(r.sign):
        return f"sign must be finite, got {r.sign}"
    if r.kind == "scalar":
        return "" if 0 <= r.a < scalars else f"a must be the index of one of the {scalars} scalars, got {r.a}"
    if r.kind == "difference" and r.b < 0 <= r.c:
        return "c needs b: the lower of b and c, or b alone"
    used = {"difference": "abc"[: 1 + (r.b >= 0) + (r.c >= 0)], "bend": "abc"}.get(r.kind, "a")
    for name in used:
        if not 0 <= getattr(r, name) < points:
            return f"{name} must be the index of one of the {points} points, got {getattr(r, name)}"
    if r.kind == "difference" and r.axis not in (0, 1, 2):
        return f"axis must be 0, 1 or 2, got {r.axis}"
    return ""


def hysteresis(values: ArrayLike, low: ArrayLike, high: ArrayLike, initial: ArrayLike = False) -> np.ndarray:
    """Boolean features from values (frames,) or (frames, features) by two thresholds each:
    a feature turns on where its value is above ``high`` and off where it is below ``low``
    (low <= high); in between, and where the value is NaN, it keeps its state from the frame
    before, ``initial`` before the first.  Thresholds and ``initial`` are one per feature or
    one for all.  A bool array of ``values``' shape."""
    v = np.asarray(values) if values is not None else None
    one = v is not None and v.ndim == 1
    x = _checks.real(v[:, None] if one and v is not None else v, "values", (None, "features"))
    features = x.shape[1]
    lo = _per_feature(low, "low", features)
    hi = _per_feature(high, "high", features)
    wrong = ~(lo <= hi)
    if wrong.any():
        f = int(np.flatnonzero(wrong)[0])
        raise ValueError(f"low must be at most high for every feature, got low {lo[f]} and high {hi[f]} at {f}")
    start = _checks.flags(initial, "initial", features, np.uint8)
    on = np.empty(x.shape, dtype=np.uint8)
    status = lib.mt_hysteresis(
        c_array(x), len(x), features, c_array(lo), c_array(hi), c_array(start, "unsigned char[]"),
        c_array(on, "unsigned char[]"),
    )  # fmt: skip
    check(status, "mt_hysteresis")
    result = on.view(bool)
    return result[:, 0] if one else result


def _per_feature(value: ArrayLike, name: str, features: int) -> np.ndarray:
    a = np.asarray(value)
    if a.ndim == 0:
        a = np.full(features, a)
    array = _checks.real(a, name, (features,))
    if np.isnan(array).any():
        raise ValueError(f"{name} must not be NaN")
    return array


def pack_bits(bits: ArrayLike) -> np.ndarray:
    """Bits (frames, features) of booleans (features <= 64) as one uint64 word per frame:
    bit f of word t is bits[t, f]."""
    b = np.asarray(bits) if bits is not None else None
    if b is None or b.dtype != np.bool_:
        raise TypeError(f"bits must be a boolean array, got {'None' if b is None else f'dtype {b.dtype}'}")
    if b.ndim != 2:
        raise ValueError(f"bits must be two-dimensional of shape (frames, features), got shape {b.shape}")
    if b.shape[1] > 64:
        raise ValueError(f"bits must have at most 64 features (one uint64 word a frame), got {b.shape[1]}")
    flags = np.ascontiguousarray(b).view(np.uint8)
    words = np.empty(len(b), dtype=np.uint64)
    status = lib.mt_pack_bits(c_array(flags, "unsigned char[]"), len(b), b.shape[1], c_array(words, "uint64_t[]"))
    check(status, "mt_pack_bits")
    return words


def _words(words: ArrayLike, name: str) -> np.ndarray:
    """``words`` as a C-contiguous uint64 array (frames,): unsigned or non-negative integers."""
    a = np.asarray(words) if words is not None else None
    if a is None or (a.dtype.kind not in "iu" and a.size) or a.ndim != 1:
        raise TypeError(f"{name} must be a one-dimensional array of integers (uint64 words), got {_described(a)}")
    if a.dtype.kind == "i" and a.size and a.min() < 0:
        raise ValueError(f"{name} must not be negative (uint64 words), got {int(a.min())}")
    return np.ascontiguousarray(a, dtype=np.uint64)


def _described(a: np.ndarray | None) -> str:
    return "None" if a is None else f"dtype {a.dtype} and shape {a.shape}"


class Segments(NamedTuple):
    """Runs of equal words: ``first`` (segments,), each run's first frame, and its ``words``."""

    first: np.ndarray
    words: np.ndarray


def segments(words: ArrayLike) -> Segments:
    """The runs of equal words (frames,) of a take, as :class:`Segments` (no two in a row equal)."""
    w = _words(words, "words")
    first = np.empty(len(w), dtype=np.uintp)
    values = np.empty(len(w), dtype=np.uint64)
    count = ffi.new("size_t *")
    status = lib.mt_segments(
        c_array(w, "uint64_t[]"), len(w), c_array(first, "size_t[]"), c_array(values, "uint64_t[]"), len(w), count
    )
    check(status, "mt_segments")
    return Segments(first[: count[0]].astype(np.intp), values[: count[0]])


class FeatureIndex:
    """An inverted index of the segments of many takes: for each word, the segments that hold it.

    ``takes``: one array of words (frames,) per take (:func:`pack_bits` of its features).  Each
    take is cut into :func:`segments`; ``words``, ``first`` and ``take`` list them all, take
    after take; ``take_first`` (takes + 1) bounds each take's.  ``keys`` are the distinct words,
    ascending, and the segments of keys[i] are ``ids[offsets[i]:offsets[i + 1]]``.
    """

    def __init__(self, takes: Sequence[ArrayLike]) -> None:
        cut = [segments(_words(t, f"takes[{i}]")) for i, t in enumerate(takes)]
        self.frames = np.array([len(np.asarray(t)) for t in takes], dtype=np.intp)
        counts = np.array([len(c.first) for c in cut], dtype=np.intp)
        self.take_first = np.concatenate([[0], np.cumsum(counts)]).astype(np.uintp)
        self.words = np.concatenate([c.words for c in cut]) if cut else np.empty(0, np.uint64)
        self.first = np.concatenate([c.first for c in cut]) if cut else np.empty(0, np.intp)
        self.take = np.repeat(np.arange(len(cut)), counts)
        total = len(self.words)
        self.keys = np.empty(total, dtype=np.uint64)
        self.offsets = np.empty(total + 1, dtype=np.uintp)
        self.ids = np.empty(total, dtype=np.uintp)
        self._views = [
            c_array(self.words, "uint64_t[]"),
            c_array(self.take_first, "size_t[]"),
            c_array(self.keys, "uint64_t[]"),
            c_array(self.offsets, "size_t[]"),
            c_array(self.ids, "size_t[]"),
        ]
        x: Any = ffi.new("struct mt_feature_index *")
        self._index = x
        x.words, x.take_first, x.keys, x.offsets, x.ids = self._views
        x.segments, x.takes = total, len(cut)
        check(lib.mt_feature_index_build(x), "mt_feature_index_build")
        self.keys = self.keys[: x.nkeys]
        self.offsets = self.offsets[: x.nkeys + 1]

    def find(self, query: ArrayLike) -> np.ndarray:
        """Where the sequence of segment words ``query`` (``segments(example).words``: none
        empty) occurs, exactly, in consecutive segments of one take: an int array (hits, 3) of
        (take, first frame, stop frame), frames first .. stop-1 of the take, in take and frame
        order.  A match is of whole segments: its first and last may last longer or shorter in
        the take than in the example."""
        q = _words(query, "query")
        if not len(q):
            raise ValueError("query must hold at least one word")
        count = ffi.new("size_t *")
        hits = np.empty(0, dtype=np.uintp)
        for _ in range(2):  # the count, then the hits
            status = lib.mt_feature_index_find(
                self._index, c_array(q, "uint64_t[]"), len(q), c_array(hits, "size_t[]"), len(hits), count
            )
            check(status, "mt_feature_index_find")
            if len(hits) == count[0]:
                break
            hits = np.empty(count[0], dtype=np.uintp)
        s = hits.astype(np.intp)
        take = self.take[s]
        after = s + len(q)  # the segment after the match, if its take has one
        inside = after < self.take_first.astype(np.intp)[take + 1]
        stop = self.frames[take]
        stop[inside] = self.first[after[inside]]
        return np.stack([take, self.first[s], stop], axis=1).astype(np.intp)
