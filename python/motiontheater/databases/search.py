"""Search by example: the takes of a database that hold a motion like a query clip.

The query's relational words (:func:`.features.words`) are cut into segments of equal words; the
inverted index finds where runs of those segments occur in the database's takes, every run of
the query's segments from the whole sequence down to single segments, until the places found
lie in at least ``k`` takes (Müller, Röder and Clausen's filter, made fuzzy by taking pieces of
the query).  Each place aligns a window of the query's length, within the DTW band of it; those
windows, and only those, are ranked exactly by dynamic time warping of the pose features in a
Sakoe-Chiba band, with LB_Keogh pruning the windows that cannot win
(:func:`mtcore.search.dtw_search`).  Where the filter finds fewer than ``k`` takes, every window
of every take is ranked: a search always answers, and its distances are exact either way.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from mtcore.search import dtw, dtw_search, segments

from ..model.motion import Motion
from .features import body, moves, pose_features, words
from .index import Database, Entry

BAND = 0.2
"""The DTW band's radius as a share of the query's length (Sakoe and Chiba's 10-20 %)."""
SHORTEST_QUERY = 3
"""Rows (at the feature rate) a query must span: 0.3 s."""


@dataclass(frozen=True)
class Hit:
    """A take's window most like the query: ``take`` as indexed, frames ``first`` .. ``last`` as
    the file numbers them, and the ``distance``: the DTW distance (the sum of squared feature
    distances along the warping path) per row of the query, so that a take shorter than the
    query (compared whole with the whole query, its band widened by the difference) ranks with
    the windows of the others; 0 for the query itself."""

    take: str
    first: int
    last: int
    distance: float

    def as_dict(self) -> dict:
        """The hit as ``--json`` prints it."""
        return {"take": self.take, "first": self.first, "last": self.last, "distance": self.distance}


@dataclass(frozen=True)
class Found:
    """The hits, best first, and how they were found: ``windows`` ranked of ``total`` windows in
    the takes searched, ``filtered`` whether the index chose them (else every window was ranked),
    ``warped`` the windows whose DTW was computed (the rest pruned by their lower bound), and
    ``whole`` the takes shorter than the query, each warped whole against it."""

    hits: tuple[Hit, ...]
    windows: int
    total: int
    filtered: bool
    warped: int
    whole: int = 0


def search(
    database: Database,
    query: Motion,
    k: int = 10,
    *,
    band: float = BAND,
    exclude: Callable[[str], bool] | None = None,
    use_index: bool = True,
) -> Found:
    """The ``k`` takes of ``database`` (those ``exclude`` does not exclude) whose windows are
    nearest the query clip by DTW, one hit per take, best first (see the module docstring);
    ``use_index=False`` ranks every window, as the index's filter does when it finds too few."""
    if isinstance(k, bool) or not isinstance(k, int) or k < 1:
        raise ValueError(f"k must be a whole number >= 1, got {k!r}")
    if not (isinstance(band, (int, float)) and 0 <= band <= 1):
        raise ValueError(f"band must be a share of the query's length from 0 to 1, got {band!r}")
    b = body(query)
    q = pose_features(b).astype(np.float64)
    m = len(q)
    if m < SHORTEST_QUERY:
        raise ValueError(
            f"the query spans {query.frames} frame(s) ({query.frames / query.frame_rate:.2g} s): search needs at least "
            f"{SHORTEST_QUERY / 10:.1f} s of motion"
        )
    radius = max(1, math.ceil(band * m))
    searched = [i for i, e in enumerate(database.entries) if exclude is None or not exclude(e.take)]
    takes = [i for i in searched if database.entries[i].rows >= m]
    every = _windows(database, takes, m)
    chosen = _filtered(database, words(b), takes, m, radius, k) if use_index else None
    starts = chosen if chosen is not None else every
    hits, warped = _longer(database, q, starts, radius, k)
    shorter = [i for i in searched if database.entries[i].rows < m]
    for i in shorter:  # a take shorter than the query: the whole of it against the whole query
        e = database.entries[i]
        rows = database.poses[database.rows_of(e)]
        distance = dtw(q, rows, m - e.rows + radius) / m
        hits[i] = Hit(e.take, *_span(database, e, e.start, e.rows), distance)
    ranked = sorted(hits.values(), key=lambda h: (h.distance, h.take))[:k]
    return Found(tuple(ranked), len(starts), len(every), chosen is not None, int(warped), len(shorter))


def _longer(database: Database, q: np.ndarray, starts: np.ndarray, radius: int, k: int) -> tuple[dict, int]:
    """The best window of each of the k takes nearest the query among the windows at ``starts``."""
    m, series = len(q), database.poses
    hits: dict[int, Hit] = {}
    want, warped = k, 0
    while len(starts):
        found = dtw_search(q, series, min(want, len(starts)), radius, starts)
        warped = found.warped
        hits = {}
        for start, distance, take in zip(found.starts, found.distances, database.owner(found.starts)):
            if int(take) not in hits:
                e = database.entries[int(take)]
                hits[int(take)] = Hit(e.take, *_span(database, e, start, m), float(distance) / m)
        if len(hits) >= k or want >= len(starts):
            break
        want *= 4  # a take's neighbouring windows crowd the list: ask for more
    return hits, warped


def _span(database: Database, entry: Entry, start: int, rows: int) -> tuple[int, int]:
    """The take's frames that rows start .. start + rows - 1 stand for: each row its frame and
    those up to the next row's (the last row of a take, up to its last frame)."""
    end = start + rows
    last = database.frames[end] - 1 if end < entry.start + entry.rows else entry.last_frame
    return int(database.frames[start]), int(last)


def _windows(database: Database, takes: list[int], m: int) -> np.ndarray:
    """Every window of m rows within one of the takes: its first row in the database."""
    pieces = [np.arange(e.start, e.start + e.rows - m + 1) for e in (database.entries[i] for i in takes)]
    return np.concatenate(pieces).astype(np.intp) if pieces else np.empty(0, np.intp)


def _filtered(database: Database, query_words: np.ndarray, takes: list[int], m: int, radius: int, k: int):
    """The windows the index finds for runs of the query's segments (longest runs first), or
    None where they lie in fewer than k takes."""
    cut = segments(query_words)
    allowed = np.zeros(len(database.entries), bool)
    allowed[takes] = True
    n = len(cut.words)
    chosen: set[int] = set()
    for length in range(n, 0, -1):
        for j in range(n - length + 1):
            found = database.index.find(cut.words[j : j + length])
            for take, first, _ in found[allowed[found[:, 0]]] if len(found) else ():
                e = database.entries[int(take)]
                aligned = int(first) - int(cut.first[j])  # where the query would begin
                low, high = max(aligned - radius, 0), min(aligned + radius, e.rows - m)
                chosen.update(range(e.start + low, e.start + high + 1))
        rows = np.array(sorted(chosen), dtype=np.intp)
        if len(np.unique(database.owner(rows))) >= k:
            return rows
    return None


def nearest_frames(
    database: Database, query: Motion, frame: int, k: int = 10, *, exclude: Callable[[str], bool] | None = None
) -> tuple[Hit, ...]:
    """Frame search (motion matching): the ``k`` rows of ``database`` whose moves
    (:func:`.features.moves`: the feet, the hips' velocity and the path ahead, in the hips' frame)
    are nearest the query take's at ``frame`` (a frame number of the take), by squared Euclidean
    distance, exactly (a k-d tree prunes, :class:`mtcore.search.KDTree`), nearest first; each hit
    is one frame (``first`` = ``last``) of a take ``exclude`` does not exclude."""
    if isinstance(k, bool) or not isinstance(k, int) or k < 1:
        raise ValueError(f"k must be a whole number >= 1, got {k!r}")
    if not query.first_frame <= frame <= query.last_frame:
        raise ValueError(f"frame {frame} is not one of the query's frames {query.first_frame}..{query.last_frame}")
    b = body(query, frame=frame)
    row = int(np.flatnonzero(b.frames == frame)[0])
    q = moves(b)[row].astype(np.float64)
    tree = database.tree
    want = k
    while True:
        found = tree.query(q, min(want, tree.n))
        rows = found.indices[found.indices >= 0]
        owners = database.owner(rows)
        keep = [i for i, o in enumerate(owners) if exclude is None or not exclude(database.entries[int(o)].take)]
        if len(keep) >= k or want >= tree.n:
            break
        want *= 4
    return tuple(
        Hit(
            database.entries[int(owners[i])].take,
            int(database.frames[rows[i]]),
            int(database.frames[rows[i]]),
            float(found.distances[i]),
        )
        for i in keep[:k]
    )
