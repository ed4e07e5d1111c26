"""The search database: the features of every take of a collection, built once (on all cores or a
Dask cluster, again only for the takes that are new or changed) and searched by example.

A database is one ``.npz`` file (numpy's zip of arrays, written whole or not at all): for each
take its path as indexed, size and modification time (what tells a changed take), its frame
numbering and rate, and where its rows lie in three arrays that hold every take's rows one
after the other at FEATURE_RATE: ``poses`` (rows, dims) float32 (:func:`.features.pose_features`),
``moves`` (rows, 27) float32 (:func:`.features.moves`, what frame search compares), ``words``
(rows,) uint64 (:func:`.features.words`) and ``frames`` (rows,) the take's frame number of each
row.  Reading it builds the inverted index of the words' segments in C
(:class:`mtcore.search.FeatureIndex`).
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterable
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from mtcore.search import FeatureIndex, KDTree

from .._io import output
from ..formats.table import read_take
from ..model.errors import FormatError
from .batch import Progress, find_takes, run_each
from .features import FEATURE_RATE, body, moves, pose_features, words

FORMAT = "motiontheater search database 3"


class OtherVersion(ValueError):
    """A search database of another version of this format: indexing again replaces it."""


@dataclass(frozen=True)
class Entry:
    """One take of a database: ``take`` its path as indexed, ``size`` and ``mtime_ns`` as it was
    when indexed, ``first_frame``, ``last_frame`` and ``frame_rate`` as the file numbers and times its frames,
    and its rows ``start`` .. ``start + rows`` of the database's arrays."""

    take: str
    size: int
    mtime_ns: int
    first_frame: int
    last_frame: int
    frame_rate: float
    start: int
    rows: int


@dataclass(frozen=True)
class IndexJob:
    """What a worker needs to index a take."""

    take: str
    asf: str | None = None
    frame_rate: float | None = None
    unit: str | None = None
    bytes: int = 0


@dataclass(frozen=True)
class Indexed:
    """A take's features (``error``: why it has none)."""

    take: str
    poses: np.ndarray | None = None
    moves: np.ndarray | None = None
    words: np.ndarray | None = None
    frames: np.ndarray | None = None
    first_frame: int = 1
    last_frame: int = 0
    frame_rate: float = 0.0
    error: str | None = None
    bytes: int = 0


def index_job(job: IndexJob) -> Indexed:
    """Read one take and compute its features; a take that cannot be read or has no body the
    rig tables know is indexed as an error that says why."""
    try:
        motion = read_take(job.take, job.asf, job.frame_rate, job.unit, workers=1)
        b = body(motion)
    except (FormatError, ValueError, OSError, MemoryError) as e:
        return Indexed(job.take, error=str(e) if job.take in str(e) else f"{job.take}: {e}", bytes=job.bytes)
    return Indexed(
        job.take,
        pose_features(b).astype(np.float32),
        moves(b).astype(np.float32),
        words(b),
        b.frames.astype(np.int64),
        motion.first_frame,
        motion.last_frame,
        motion.frame_rate,
        bytes=job.bytes,
    )


class Database:
    """A search database (see the module docstring): ``entries`` and the rows of every take."""

    def __init__(
        self, entries: list[Entry], poses: np.ndarray, moves: np.ndarray, words: np.ndarray, frames: np.ndarray
    ):
        self.entries = entries
        self._poses = np.ascontiguousarray(poses, dtype=np.float32)
        self._moves: np.ndarray | None = moves
        self.words = words
        self.frames = frames
        self.starts = np.array([e.start for e in entries], dtype=np.intp)
        self._index: FeatureIndex | None = None
        self._tree: KDTree | None = None

    @classmethod
    def empty(cls, dims: int = 0) -> Database:
        """A database of no take, its poses of ``dims`` dimensions."""
        return cls(
            [],
            np.empty((0, dims), np.float32),
            np.empty((0, 27), np.float32),
            np.empty(0, np.uint64),
            np.empty(0, np.int64),
        )

    def __len__(self) -> int:
        return len(self.entries)

    @property
    def index(self) -> FeatureIndex:
        """The inverted index of every take's segments of equal words, built on first use."""
        if self._index is None:
            self._index = FeatureIndex([self.words[e.start : e.start + e.rows] for e in self.entries])
        return self._index

    # A database holds one copy of its rows, float32 (the kernels read them as they are): the poses
    # are DTW's series, and the moves are the k-d tree's rows once frame search has built it.
    @property
    def poses(self) -> np.ndarray:
        """The pose rows (rows, dims) float32, what DTW compares."""
        return self._poses

    @property
    def moves(self) -> np.ndarray:
        """The move rows (rows, 27) float32."""
        if self._moves is not None:
            return self._moves
        assert self._tree is not None
        moves = np.empty_like(self._tree.rows)
        moves[self._tree.index] = self._tree.rows
        return moves

    @property
    def tree(self) -> KDTree:
        """The k-d tree of every row's move (frame search), built on first use."""
        if self._tree is None:
            self._tree = KDTree(self.moves)
            self._moves = None
        return self._tree

    def owner(self, rows: np.ndarray) -> np.ndarray:
        """The entry (its index) that each database row belongs to."""
        return np.searchsorted(self.starts, rows, "right") - 1

    def rows_of(self, entry: Entry) -> slice:
        """The rows of an entry in the database's arrays."""
        return slice(entry.start, entry.start + entry.rows)

    def seconds(self) -> float:
        """The capture time the database covers."""
        return float(sum(e.rows for e in self.entries)) / FEATURE_RATE

    def save(self, path: str | os.PathLike) -> None:
        """Write the database to ``path`` (.npz), whole or not at all."""
        meta = json.dumps({"format": FORMAT, "rate": FEATURE_RATE, "entries": [asdict(e) for e in self.entries]})
        with output(path) as f:
            np.savez(f, meta=np.array(meta), poses=self.poses, moves=self.moves, words=self.words, frames=self.frames)

    @classmethod
    def load(cls, path: str | os.PathLike) -> Database:
        """The database at ``path``; ValueError naming it where it is not one."""
        try:
            with np.load(path, allow_pickle=False) as data:
                meta = json.loads(str(data["meta"]))
                if meta.get("format") != FORMAT:
                    raise OtherVersion(
                        f"{path}: a search database of another version ({meta.get('format')!r}, this is "
                        f"{FORMAT!r}): index the takes again"
                    )
                entries = [Entry(**e) for e in meta["entries"]]
                return cls(entries, data["poses"], data["moves"], data["words"], data["frames"])
        except FileNotFoundError:
            raise ValueError(f"{path}: no such database (motiontheater index writes one)") from None
        except (OSError, KeyError, TypeError, ValueError) as e:
            if isinstance(e, OtherVersion):
                raise
            why = f": {e.strerror}" if isinstance(e, OSError) and e.strerror else ""
            raise ValueError(
                f"{path}: not a motiontheater search database (motiontheater index writes one){why}"
            ) from None


@dataclass(frozen=True)
class Built:
    """What :func:`build` did: the database, the takes indexed anew, kept, dropped (gone from the
    inputs) and failed (take, why)."""

    database: Database
    indexed: tuple[str, ...]
    kept: tuple[str, ...]
    dropped: tuple[str, ...]
    failed: tuple[tuple[str, str], ...]


def build(
    inputs: Iterable[str],
    previous: Database | None = None,
    *,
    asf: str | None = None,
    frame_rate: float | None = None,
    unit: str | None = None,
    workers: int = 0,
    scheduler: str | None = None,
    dask_local: bool = False,
    progress: bool = False,
) -> Built:
    """The database of every AMC and BVH take under ``inputs``: the rows of ``previous`` for the
    takes whose size and modification time are as it recorded, the others indexed on
    ``workers`` processes (0: every core), the Dask cluster at ``scheduler`` or a local one;
    ``progress``: a progress bar on a terminal's standard error."""
    known = {e.take: e for e in previous.entries} if previous is not None else {}
    takes, jobs, kept = [], [], []
    for take, _ in find_takes(inputs):
        path = os.fspath(take)
        try:
            stat = os.stat(path)
        except OSError:
            stat = None
        takes.append((path, stat))
        old = known.get(path)
        if old is not None and stat is not None and (old.size, old.mtime_ns) == (stat.st_size, stat.st_mtime_ns):
            kept.append(path)
        else:
            jobs.append(IndexJob(path, asf, frame_rate, unit, stat.st_size if stat else 0))
    bar = Progress(len(jobs), sum(j.bytes for j in jobs), enabled=None if progress else False)
    done: dict[str, Indexed] = {}
    try:
        for job, result in run_each(jobs, index_job, workers, scheduler=scheduler, dask_local=dask_local):
            done[job.take] = result
            bar.advance(result)  # type: ignore[arg-type]
    finally:
        bar.close()
    pieces: list[tuple[np.ndarray, ...]] = []
    entries, failed, start = [], [], 0
    for path, stat in takes:
        if path in done:
            r = done[path]
            if r.error is not None or r.poses is None or r.moves is None or r.words is None or r.frames is None:
                failed.append((path, r.error or "no features"))
                continue
            piece, frames, rate = (r.poses, r.moves, r.words, r.frames), (r.first_frame, r.last_frame), r.frame_rate
        else:
            assert previous is not None
            old = known[path]
            rows = previous.rows_of(old)
            piece = (previous.poses[rows], previous.moves[rows], previous.words[rows], previous.frames[rows])
            frames, rate = (old.first_frame, old.last_frame), old.frame_rate
        assert stat is not None
        n = len(piece[2])
        entries.append(Entry(path, stat.st_size, stat.st_mtime_ns, *frames, rate, start, n))
        pieces.append(piece)
        start += n
    dims = pieces[0][0].shape[1] if pieces else (previous.poses.shape[1] if previous is not None else 0)
    database = (
        Database(entries, *(np.concatenate([p[i] for p in pieces]) for i in range(4)))
        if pieces
        else Database.empty(dims)
    )
    listed = {path for path, _ in takes}
    dropped = tuple(t for t in known if t not in listed)
    indexed = tuple(t for t in done if done[t].error is None)
    return Built(database, indexed, tuple(kept), dropped, tuple(failed))


def open_or_empty(path: str | os.PathLike) -> Database | None:
    """The database at ``path`` if there is one, else None (nothing there, or a database of
    another version, which indexing replaces); ValueError for a file that is not a database."""
    if not Path(path).exists():
        return None
    try:
        return Database.load(path)
    except OtherVersion:
        return None
