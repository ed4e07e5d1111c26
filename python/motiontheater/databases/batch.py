"""Batch processing of capture databases: many takes, all cores or a Dask cluster, bounded memory.

A pipeline of steps (a recipe; ``motiontheater steps`` lists them) is
applied to every AMC and BVH take found under the inputs (files, folders
searched recursively, globs); results go to an output folder that mirrors
the input tree, each written to a temporary name and renamed when complete.
A take larger than a threshold is streamed in chunks of frames when its
pipeline allows (:mod:`motiontheater.editing.streaming`), so memory does not grow
with its length, to the same bytes as processing it whole.  A manifest in
the output folder records what made each output, so that ``--resume`` skips
exactly the takes already done by the same recipe from the same inputs.
This module keeps jobs, pools, progress and reports; formats and steps live
elsewhere.
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import glob
import hashlib
import json
import logging
import multiprocessing
import os
import signal
import sys
import tempfile
import threading
import time
from collections import Counter
from collections.abc import Callable, Generator, Iterable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, TypeVar

from tqdm import tqdm

from mtcore import cpu_count, share_cores

from .._io import WRITE_ERRORS, OutputError, output, read_source, regular_file, remove_stale_partials
from .._signals import terminate_as_interrupt
from ..editing.pipeline import Pipeline
from ..editing.streaming import CHUNK_FRAMES, stream, streamable
from ..formats.table import (
    FORMATS,
    companion_needed,
    companion_path,
    file_bytes,
    format_of,
    read_file,
    read_skeleton,
    require_frames,
    skeleton_for,
    suffix_for,
    take_suffixes,
    write_take,
    write_take_with_skeleton,
)
from ..model.errors import FormatError
from ..model.motion import Motion
from ..model.rig import choose_body

STREAM_ABOVE = 256 << 20  # bytes of AMC above which a take is streamed (when its pipeline allows)
MANIFEST = ".motiontheater-batch.jsonl"
_OLD_MANIFEST = ".motiontheater-batch.json"  # version 1, one JSON object: read where there is no other
Stamp = tuple[int, int]  # a file's modification time (ns) and size: it has not changed while they hold

T = TypeVar("T")
R = TypeVar("R")


@dataclass(frozen=True)
class Job:
    """One take to process: where it is, where its result goes (``output`` mirrors the take's path
    and keys the manifest; ``written`` has the suffix of what the recipe makes)."""

    input: str
    output: str
    skeleton: str  # the AMC's ASF; "" for a BVH
    pipeline: Pipeline
    frame_rate: float | None = None
    stream_above: int = STREAM_ABOVE
    chunk_frames: int = CHUNK_FRAMES
    bytes: int = 0  # the take's size when planned
    unit: str | None = None  # the takes' length unit (--unit), when given
    body: str | None = None  # the joint that carries the body (--body), when given
    allow_nan: bool = False  # results holding NaN or inf are written (--allow-nan), not refused
    stamps: tuple[Stamp, Stamp | None] | None = None  # the take's and its skeleton's when planned
    written: str = ""  # the file its result goes to, named when planned (default: output)
    replace: bool = False  # a skeleton file beside the output holding another skeleton is replaced (--in-place)


@dataclass
class Result:
    """What became of one take: where it went, whether it worked, and what it cost."""

    input: str
    output: str
    ok: bool = True
    skipped: bool = False
    no_recipe: bool = False  # a folder of recipes holds none for this take: nothing to do
    streamed: bool = False
    error: str = ""
    bytes: int = 0
    frames: int = 0
    seconds: float = 0.0
    stop: str = ""  # an output problem that every take would meet: the run stops
    written: int = 0  # the output's size
    digest: str = ""  # the input's content (SHA-256), for --resume to know a touched but unchanged take
    notes: list[tuple[int, str]] = field(default_factory=list)  # what the steps logged: (level, message)


def find_takes(inputs: Iterable[str]) -> list[tuple[Path, Path]]:
    """(take, its path relative to the output folder) for every AMC and BVH under the inputs.

    One input folder (or files and globs of one folder) mirrors into the output folder itself;
    several mirror into a subfolder each, named as the folder (or, where two share a name, as its
    path below the folder they have in common), so that their takes never meet.  A file named as
    a take that is not one (a FIFO, a device, a symlink loop) is listed, for the plan to report; a
    take named twice (through a link, or by another path) is listed once."""
    found: dict[str, tuple[Path, str, Path]] = {}  # a take's key -> (the take, the folder it mirrors from, below it)
    suffixes = take_suffixes()
    _same = _path_keys()
    for item in inputs:
        wild = next((i for i, c in enumerate(item) if c in "*?["), None)
        if wild is not None:
            # outputs mirror the tree below the folder the pattern starts in
            prefix = item[:wild]
            base = Path(prefix) if prefix.endswith(os.sep) else Path(prefix).parent
            for match in sorted(glob.glob(item, recursive=True)):
                if match.lower().endswith(suffixes) and not os.path.isdir(match):
                    found.setdefault(_same(match), (Path(match), os.path.abspath(base), Path(match).relative_to(base)))
        elif os.path.isdir(item):
            for path in sorted(Path(item).rglob("*")):
                if path.suffix.lower() in suffixes and not path.is_dir():
                    found.setdefault(_same(path), (path, os.path.abspath(item), path.relative_to(item)))
        elif os.path.lexists(item):
            found.setdefault(_same(item), (Path(item), os.path.dirname(os.path.abspath(item)), Path(Path(item).name)))
        else:
            raise FileNotFoundError(f"no file, folder or glob match: {item}")
    below = _mirrors({base for _, base, _ in found.values()})
    return [(take, below[base] / relative) for take, base, relative in found.values()]


def _mirrors(folders: set[str]) -> dict[str, Path]:
    """The subfolder of the output folder that each input folder mirrors into (see find_takes)."""
    if len(folders) <= 1:
        return {folder: Path() for folder in folders}
    names = {folder: Path(os.path.basename(folder)) for folder in folders}
    if len(set(names.values())) == len(folders) and Path() not in names.values():
        return names
    common = os.path.commonpath(list(folders))
    return {folder: Path(os.path.relpath(folder, common)) for folder in folders}


class Manifest:
    """What made each output of a folder: the recipe, and the stamps of the take and its skeleton.

    Kept beside the outputs as JSON lines, one per output, each appended as its take finishes (a
    run killed at any moment keeps every line it wrote whole; a later line for an output replaces
    an earlier one); ``--resume`` trusts an output only when the manifest says the same recipe
    made it from inputs that have not changed since.
    """

    def __init__(self, folder: str | os.PathLike):
        self.path = Path(folder) / MANIFEST
        self.entries: dict[str, dict[str, Any]] = {}
        self._log: Any = None
        for path in (self.path, Path(folder) / _OLD_MANIFEST):
            with contextlib.suppress(OSError, UnicodeDecodeError):
                status = path.stat()
                self.entries = dict(_read_manifest(str(path), status.st_mtime_ns, status.st_size))
                break

    def _key(self, job: Job) -> str:
        return _relative(job.output, self.path.parent)

    def _stamps(self, job: Job) -> dict[str, Any]:
        take, skeleton = job.stamps or (
            _stamp(os.stat(job.input)),
            _stamp(os.stat(job.skeleton)) if job.skeleton else None,
        )
        return {
            "recipe": _recipe_digest(job.pipeline),
            "input": os.path.abspath(job.input),
            "stamps": [list(take), list(skeleton) if skeleton else None],  # as JSON has them
        }

    def done(self, job: Job) -> bool:
        """Whether the job's output exists, made by this recipe from these very inputs: inputs
        whose times and sizes are those the manifest noted, or, where only a time differs (a file
        touched, copied or checked out again), whose contents are."""
        entry = self.entries.get(self._key(job))
        now = self._stamps(job)
        if entry is None or {k: entry.get(k) for k in ("recipe", "input")} != {k: now[k] for k in ("recipe", "input")}:
            return False
        if entry.get("stamps") != now["stamps"] and not self._same_contents(job, entry, now["stamps"]):
            return False
        written = Path(self.path.parent, entry["written"])
        return written.exists() and written.stat().st_size == entry["size"]

    def _same_contents(self, job: Job, entry: dict[str, Any], stamps: list[Any]) -> bool:
        noted, digests = entry.get("stamps"), entry.get("digests")
        if not isinstance(noted, list) or not isinstance(digests, list) or len(noted) != 2 or len(digests) != 2:
            return False
        sizes = [s[1] if isinstance(s, list) and len(s) == 2 else None for s in noted]
        if sizes != [s[1] if s else None for s in stamps]:  # a new size is new content: no need to read it
            return False
        with contextlib.suppress(OSError):
            return digests == self._digests(job, _digest(job.input))
        return False

    def _digests(self, job: Job, take: str) -> list[str | None]:
        skeleton = job.stamps[1] if job.stamps else None
        if job.skeleton and skeleton is None:
            skeleton = _stamp(os.stat(job.skeleton))
        return [take, _skeleton_digest(job.skeleton, skeleton) if job.skeleton else None]

    def record(self, job: Job, result: Result) -> None:
        """Note a finished job: a line appended to the manifest now."""
        key = self._key(job)
        self.entries[key] = entry = {
            **self._stamps(job),
            "written": _relative(result.output, self.path.parent),
            "size": result.written,  # measured by the worker that wrote it
        }
        if result.digest:
            with contextlib.suppress(OSError):
                entry["digests"] = self._digests(job, result.digest)
        if self._log is None:  # the manifest as found, compacted (atomically, like every output), then appended to
            with output(self.path) as f:
                f.write(b"".join(_manifest_line(k, e) for k, e in self.entries.items() if k != key))
            with contextlib.suppress(OSError):  # what a version-1 manifest held is in this one now
                (self.path.parent / _OLD_MANIFEST).unlink(missing_ok=True)
            self._log = open(self.path, "ab")  # noqa: SIM115 (appended to line by line, closed by close())
        self._log.write(_manifest_line(key, entry))
        self._log.flush()

    def close(self) -> None:
        """Stop appending (the lines written are all there already)."""
        if self._log is not None:
            self._log.close()
            self._log = None


def _relative(path: str, folder: Path) -> str:
    """os.path.relpath of a path below the folder (as outputs are), without its system calls."""
    prefix = os.path.join(folder, "")
    return path[len(prefix) :] if path.startswith(prefix) else os.path.relpath(path, folder)


def _manifest_line(key: str, entry: dict[str, Any]) -> bytes:
    return json.dumps({"output": key, **entry}).encode() + b"\n"


@functools.lru_cache(maxsize=64)
def _recipe_digest(pipeline: Pipeline) -> str:
    """What the manifest notes of the recipe that made an output: its TOML's SHA-256."""
    return hashlib.sha256(pipeline.to_toml().encode()).hexdigest()


@functools.lru_cache(maxsize=2)
def _read_manifest(path: str, mtime_ns: int, size: int) -> dict[str, dict[str, Any]]:
    """A manifest file's entries, parsed once while the file stays as it was: the plan reads it
    to skip what is done, and the run that follows needs the same entries to compact it."""
    with open(path, encoding="utf-8") as f:
        return _manifest_entries(f.read())


def _manifest_entries(text: str) -> dict[str, dict[str, Any]]:
    """The entries of a manifest's text: JSON lines, the last for an output counting; a line that is
    not whole JSON (a run killed as it wrote it) is skipped.  (Version 1 was one JSON object.)"""
    with contextlib.suppress(ValueError):
        whole = json.loads(text)
        if isinstance(whole, dict) and whole.get("version") == 1:
            return dict(whole.get("outputs", {}))
    entries = {}
    for line in text.splitlines():
        with contextlib.suppress(ValueError, TypeError, KeyError, AttributeError):  # not an entry: skipped
            entry = json.loads(line)
            entries[entry.pop("output")] = entry
    return entries


def plan_jobs(
    inputs: Iterable[str],
    out: str | os.PathLike,
    pipeline: Pipeline | None,
    *,
    recipes: str | os.PathLike | None = None,
    skeleton: str | None = None,
    frame_rate: float | None = None,
    resume: bool = False,
    in_place: bool = False,
    stream_above: int = STREAM_ABOVE,
    chunk_frames: int = CHUNK_FRAMES,
    unit: str | None = None,
    body: str | None = None,
    allow_nan: bool = False,
) -> tuple[list[Job], list[Result]]:
    """The jobs to run, and the takes settled before running (not a regular file, no skeleton, or
    already done by this recipe when resuming).  Each take runs ``pipeline``, or with
    ``recipes``, a folder, its own recipe there (its path below the inputs with .toml added, as
    ``check --recipes`` writes them; a take with none is settled as having nothing to do).  Every take's output is named before any is
    written, and the run is refused (ValueError naming both files) where an output would replace
    an input (its own, unless ``in_place``) or a skeleton the takes are read with, or where two
    takes would write the same file."""
    found = find_takes(inputs)
    candidates, settled = [], []
    folders: dict[Path, list[Path]] = {}  # the ASFs of each folder, listed once
    skeleton_stamps: dict[Path, Stamp] = {}
    reads: dict[Identity, str] = {}  # every file the run reads
    if (pipeline is None) == (recipes is None):
        raise ValueError("give one pipeline for every take, or a folder of recipes, one per take")
    for take, relative in found:
        target = Path(out) / relative
        own = pipeline
        if recipes is not None:
            recipe = Path(recipes) / f"{relative.as_posix()}.toml"
            if not recipe.is_file():
                settled.append(Result(str(take), str(target), no_recipe=True))
                continue
            try:
                own = Pipeline.read(recipe)
            except (OSError, ValueError) as e:  # a recipe that cannot be read fails its take alone
                said = str(e)
                settled.append(
                    Result(str(take), str(target), ok=False, error=said if str(recipe) in said else f"{recipe}: {said}")
                )
                continue
        assert own is not None
        try:
            status = regular_file(take)
            reads.setdefault(_identity(status), str(take))
            asf = skeleton_for(take, skeleton, folders)
            if asf is not None and asf not in skeleton_stamps:
                asf_status = regular_file(asf)
                skeleton_stamps[asf] = _stamp(asf_status)
                reads.setdefault(_identity(asf_status), str(asf))
        except OSError as e:
            with contextlib.suppress(OSError):
                reads.setdefault(_identity(os.lstat(take)), str(take))
            settled.append(Result(str(take), str(target), ok=False, error=str(e)))
            continue
        candidates.append(
            Job(
                str(take),
                str(target),
                str(asf) if asf else "",
                own,
                frame_rate,
                stream_above,
                chunk_frames,
                status.st_size,
                unit,
                body,
                allow_nan,
                (_stamp(status), skeleton_stamps[asf] if asf else None),
                replace=in_place,
            )
        )
    keys = _path_keys()
    candidates = _name_outputs(candidates, keys)
    _refuse_clashes(candidates, reads, in_place, keys)
    manifest = Manifest(out)
    jobs = []
    for job in candidates:
        if resume and manifest.done(job):
            settled.append(Result(job.input, job.output, skipped=True, bytes=job.bytes))
        else:
            jobs.append(job)
    return jobs, settled


def _name_outputs(jobs: list[Job], key: Callable[[str], str]) -> list[Job]:
    """The jobs with the file each one writes: its take's name, with the suffix of what the recipe
    makes (an exporter's, or the format of the result's skeleton).  Where takes of one name in
    different formats would make the same file (``01_01.amc`` and ``01_01.bvh`` -> ``01_01.csv``),
    each keeps its take's suffix before the new one (``01_01.amc.csv``, ``01_01.bvh.csv``)."""

    @functools.cache
    def made(pipeline: Pipeline, take: str) -> str:
        """The suffix of what the pipeline makes of a take of this suffix."""
        exporter = pipeline.exporter
        if exporter is not None:
            chosen = dict(exporter.options).get("format")
            return f".{chosen}" if chosen else exporter.step.suffixes[0]
        return suffix_for(pipeline.convention(FORMATS[take].convention))

    def named(job: Job, keep: bool) -> str:
        stem, suffix = os.path.splitext(job.output)
        new = made(job.pipeline, suffix.lower())
        if new == suffix.lower():  # the take's own format: its suffix as the file spells it (.AMC stays .AMC)
            new = suffix
        return stem + (suffix if keep else "") + new

    plain = [named(job, False) for job in jobs]
    keys = [key(path) for path in plain]
    shared = {k for k, count in Counter(keys).items() if count > 1}
    return [
        dataclasses.replace(job, written=named(job, True) if k in shared else path)
        for job, path, k in zip(jobs, plain, keys)
    ]


def _refuse_clashes(jobs: list[Job], reads: dict[Identity, str], in_place: bool, key: Callable[[str], str]) -> None:
    """ValueError naming both files where an output is a file the run reads (a take, or a skeleton
    takes are read with), where two takes write one file, or where a take's skeleton would be
    copied over another skeleton file beside the outputs."""
    claimed: dict[str, str] = {}
    for job in jobs:
        other = claimed.setdefault(key(job.written), job.input)
        if other != job.input:
            raise ValueError(
                f"{other} and {job.input} would both be written to {job.written}: "
                "process them into separate output folders"
            )
        source = _read_at(job.written, reads)
        if source == job.input and not in_place:
            raise ValueError(
                f"{job.input} would be overwritten by its own output: choose another output folder, "
                "or pass --in-place to replace the takes"
            )
        if source not in (None, job.input):
            raise ValueError(
                f"{job.written}, the output of {job.input}, would replace {source}, which this run reads: "
                "choose an output folder where no input lies"
            )
    copied: dict[str, str] = {}  # each file beside the outputs a skeleton is copied to -> that skeleton
    for job in jobs:
        if not job.skeleton or job.pipeline.exporter is not None or format_of(job.written).companion is None:
            continue
        target = os.path.join(os.path.dirname(job.written), os.path.basename(job.skeleton))
        earlier = copied.get(place := key(target))
        if earlier is not None:  # looked at already, for a take before
            if earlier != job.skeleton and file_bytes(earlier) != file_bytes(job.skeleton):
                raise ValueError(
                    f"{earlier} and {job.skeleton} would both be copied to {target}: "
                    "process their takes into separate output folders"
                )
            continue
        copied[place] = job.skeleton
        source = _read_at(target, reads)
        if source == job.skeleton:
            continue  # the skeleton itself: nothing is copied
        data = file_bytes(job.skeleton)
        assert data is not None  # the plan found it a file
        if source is not None and file_bytes(target) != data:
            raise ValueError(
                f"{target}, the skeleton of {job.input} copied beside its output, would replace {source}, "
                "which this run reads: choose an output folder where no input lies"
            )
        companion_needed(target, data, replace=in_place)  # another skeleton there: refused now, not per take


Identity = tuple[int, int]  # a file's device and inode: the same for every path that reaches it


def _identity(status: os.stat_result) -> Identity:
    return status.st_dev, status.st_ino


def _read_at(path: str, reads: dict[Identity, str]) -> str | None:
    """The input of the run that is the file at ``path`` (through any link), or None."""
    try:
        return reads.get(_identity(os.stat(path)))
    except OSError:
        return None


def _path_keys() -> Callable[[str | os.PathLike], str]:
    """A function giving the key of a path that may not exist yet: two paths of one place (through
    linked folders, or of another case where case does not count) have one key.  Each folder's
    real path is looked up once (thousands of takes share a few folders)."""
    real = functools.lru_cache(maxsize=None)(os.path.realpath)

    def key(path: str | os.PathLike) -> str:
        folder, name = os.path.split(os.fspath(path))
        return os.path.normcase(os.path.join(real(folder or os.curdir), name))

    return key


def run_job(job: Job) -> Result:
    """Process one take; every failure becomes a Result naming the file, line and reason."""
    start = time.perf_counter()
    result = Result(job.input, job.output, bytes=job.bytes)
    with _notes_into(result.notes):
        _run_job(job, result)
    result.seconds = time.perf_counter() - start
    return result


def _run_job(job: Job, result: Result) -> None:
    try:
        try:
            os.makedirs(os.path.dirname(job.output) or ".", exist_ok=True)
        except OSError as e:
            raise OutputError(e.errno, f"cannot write {os.path.dirname(job.output)}: {e.strerror}") from None
        if job.skeleton and job.bytes > job.stream_above and streamable(job.pipeline):
            skeleton = read_skeleton(job.skeleton, job.unit)
            _copy_skeleton(job.skeleton, os.path.dirname(job.output), job.replace)
            result.output = job.written or job.output
            result.frames = stream(
                job.input, result.output, skeleton, job.pipeline, job.frame_rate, chunk_frames=job.chunk_frames
            )
            result.streamed = True
        else:
            motion = require_frames(_read(job), job.input)
            result.output = _write(job, job.pipeline.apply(motion), motion)
            result.frames = motion.frames
        result.written = os.path.getsize(result.output)
        result.digest = _digest(job.input)
    except OutputError as e:
        result.ok, result.error = False, str(e)
        result.stop = str(e) if e.errno in WRITE_ERRORS else ""
    except (FormatError, ValueError, OSError) as e:
        result.ok, result.error = False, str(e)
    except MemoryError:
        result.ok, result.error = False, f"{job.input}: not enough memory for this take ({job.bytes / 1e6:.0f} MB)"


_taking_notes = threading.local()  # the notes list of the take this thread processes, if any


class _TakeNotes(logging.Filter):
    """On the package's logger: a record logged while a take is processed goes to its notes, for
    the parent to log again naming the take (the command line prints it above the bar), not to the
    handlers (in a worker: its stderr, over the bar)."""

    def filter(self, record: logging.LogRecord) -> bool:
        notes = getattr(_taking_notes, "notes", None)
        if notes is None:
            return True
        notes.append((record.levelno, record.getMessage()))
        return False


_LOG = logging.getLogger("motiontheater")
_LOG.addFilter(_TakeNotes())


@contextlib.contextmanager
def _notes_into(notes: list[tuple[int, str]]) -> Generator[None]:
    """Keep what the package logs in this thread (at INFO and above, as the command line prints) in ``notes``."""
    level = _LOG.level
    _taking_notes.notes = notes
    if _LOG.getEffectiveLevel() > logging.INFO:  # a Dask worker's, which the command line did not set
        _LOG.setLevel(logging.INFO)
    try:
        yield
    finally:
        _taking_notes.notes = None
        _LOG.setLevel(level)


def _read(job: Job) -> Motion:
    skeleton = read_skeleton(job.skeleton, job.unit) if job.skeleton else None
    # with the recipe's whole_frames, a file that breaks off: its whole frames
    motion, _ = read_file(job.input, skeleton, job.frame_rate, job.unit, 1, whole_frames=job.pipeline.whole_frames)
    return motion if job.body is None else choose_body(motion, job.body)


def _write(job: Job, result: Motion, motion: Motion) -> str:
    """Write a take's result where the job says, an AMC with its skeleton beside it; returns the path."""
    target = job.written or job.output
    if job.pipeline.exporter is not None:
        job.pipeline.write(result, target)
    elif result.skeleton is motion.skeleton and job.skeleton and companion_path(result, target) is not None:
        _copy_skeleton(job.skeleton, os.path.dirname(target), job.replace)
        write_take(result, target, allow_non_finite=job.allow_nan)
    else:
        write_take_with_skeleton(result, target, allow_non_finite=job.allow_nan, replace=job.replace)
    return target


def _stamp(status: os.stat_result) -> Stamp:
    return status.st_mtime_ns, status.st_size


@functools.lru_cache(maxsize=64)
def _skeleton_digest(path: str, stamp: Stamp) -> str:
    """A skeleton file's digest, once per version of it (a database's takes share a few)."""
    return _digest(path)


def _digest(path: str) -> str:
    found = hashlib.sha256()
    with open(path, "rb") as f:
        while chunk := f.read(1 << 20):
            found.update(chunk)
    return found.hexdigest()


def _copy_skeleton(asf: str, folder: str, replace: bool = False) -> None:
    """The skeleton beside the outputs that use it, so that the output folder stands alone; a file
    there holding another skeleton is kept (ValueError) unless ``replace``."""
    target = os.path.join(folder, os.path.basename(asf))
    if os.path.abspath(target) == os.path.abspath(asf):
        return
    data = read_source(asf)[0]
    if companion_needed(target, data, replace=replace):
        with output(target) as dst:
            dst.write(data)


class Progress:
    """A progress bar on stderr (takes and MB, rate, time left), fitting the terminal (tqdm's); off
    when stderr is not a terminal."""

    def __init__(self, files: int, total_bytes: int, enabled: bool | None = None):
        enabled = sys.stderr.isatty() if enabled is None else enabled
        self.bar = None
        if enabled:
            self.bar = tqdm(
                total=total_bytes, unit="B", unit_scale=True, unit_divisor=1000, file=sys.stderr,
                desc=f"0/{files} takes", dynamic_ncols=True, smoothing=0.1,
            )  # fmt: skip
        self.files, self.done = files, 0

    def advance(self, result: Result) -> None:
        """Count a finished take."""
        self.done += 1
        if self.bar is not None:
            self.bar.set_description(f"{self.done}/{self.files} takes", refresh=False)
            self.bar.update(result.bytes)

    def close(self) -> None:
        """Take the bar off the screen's last line."""
        if self.bar is not None:
            self.bar.close()


@dataclass
class Summary:
    """Every take's result and the run's time: what the batch command reports."""

    results: list[Result] = field(default_factory=list)
    seconds: float = 0.0
    planned: int = 0  # takes found
    stopped: str = ""  # why the run stopped early, if it did
    interrupted: bool = False

    @property
    def failed(self) -> list[Result]:
        """The takes that failed."""
        return [r for r in self.results if not r.ok]

    def as_dict(self) -> dict:
        """The totals and failures, ready for JSON."""
        done = [r for r in self.results if r.ok and not r.skipped and not r.no_recipe]
        processed = sum(r.bytes for r in done)
        return {
            "files": self.planned or len(self.results),
            "processed": len(done),
            "skipped": sum(r.skipped for r in self.results),
            "without_recipe": sum(r.no_recipe for r in self.results),
            "failed": len(self.failed),
            "not_run": max(0, self.planned - len(self.results)),
            "streamed": sum(r.streamed for r in self.results),
            "megabytes": processed / 1e6,
            "seconds": self.seconds,
            "megabytes_per_second": processed / 1e6 / self.seconds if self.seconds else 0.0,
            "stopped": self.stopped,
            "interrupted": self.interrupted,
            "failures": [{"file": r.input, "error": r.error} for r in self.failed if not r.stop],
        }

    def text(self) -> str:
        """The totals in a line, then a line per failure, and why the run ended early if it did."""
        d = self.as_dict()
        totals = (
            f"{d['processed']} processed, {d['skipped']} skipped (already done), "
            + (f"{d['without_recipe']} without a recipe (nothing to fix), " if d["without_recipe"] else "")
            + f"{d['failed']} failed of {d['files']} takes"
        )
        if d["processed"]:  # a rate of nothing done says nothing
            totals += f"; {d['megabytes']:.1f} MB in {d['seconds']:.1f} s ({d['megabytes_per_second']:.1f} MB/s)"
        lines = [totals]
        lines += [
            f"FAILED {f['error']}" if f["file"] in f["error"] else f"FAILED {f['file']}: {f['error']}"
            for f in d["failures"]
        ]
        if self.stopped:
            lines.append(f"STOPPED: {self.stopped}; {d['not_run']} takes were not processed")
        if self.interrupted:
            lines.append(f"INTERRUPTED: {d['not_run']} takes not processed; run the same command with --resume")
        return "\n".join(lines)


def run(
    jobs: list[Job],
    settled: list[Result],
    *,
    workers: int = 0,
    scheduler: str | None = None,
    dask_local: bool = False,
    progress: Progress | None = None,
    out: str | os.PathLike = ".",
) -> Summary:
    """Run the jobs on local processes (``workers``, 0 for every core), a Dask cluster at
    ``scheduler``, or a local Dask cluster; the summary lists every take's result.

    The output folder is checked first (one clear OutputError if it cannot be written), a
    problem that every take would meet (no permission, disk full) stops the run once, and an
    interruption (Ctrl-C, SIGTERM) ends it cleanly: no partial file is left, the manifest keeps
    what was done, and the summary says so (``interrupted``)."""
    summary = Summary(list(settled), planned=len(settled) + len(jobs))
    progress = progress or Progress(len(jobs), sum(j.bytes for j in jobs), enabled=False)
    manifest = Manifest(out) if jobs else None
    _check_writable(out)
    start = time.perf_counter()
    remove_stale_partials(out, recursive=True)
    results = run_each(jobs, run_job, workers, scheduler=scheduler, dask_local=dask_local)
    try:
        for job, result in results:
            summary.results.append(result)
            for level, note in result.notes:
                _LOG.log(level, "%s: %s", result.input, note)
            progress.advance(result)
            if result.ok and manifest is not None:
                manifest.record(job, result)
            if result.stop:
                summary.stopped = result.stop
                break
    except KeyboardInterrupt:
        summary.interrupted = True
    finally:
        results.close()
        progress.close()
        if manifest is not None:
            manifest.close()
        remove_stale_partials(out, recursive=True)
    summary.seconds = time.perf_counter() - start
    return summary


def _check_writable(out: str | os.PathLike) -> None:
    """OutputError now, once, if the output folder cannot be made or written to."""
    try:
        os.makedirs(out, exist_ok=True)
        tempfile.TemporaryFile(dir=os.fspath(out)).close()
    except OSError as e:
        raise OutputError(e.errno, f"cannot write to the output folder {os.fspath(out)}: {e.strerror}") from None


def run_each(
    items: list[T], work: Callable[[T], R], workers: int = 0, *, scheduler: str | None = None, dask_local: bool = False
) -> Generator[tuple[T, R]]:
    """(item, work(item)) for each item as it is done: on local processes (``workers``, 0 for every
    core; in this process for one worker or one item), a Dask cluster at ``scheduler``, or a local
    Dask cluster.  ``work`` is a module-level function (the workers import it)."""
    if scheduler or dask_local:
        yield from _run_dask(items, work, workers, scheduler)
        return
    count = workers or cpu_count()
    if count == 1 or len(items) <= 1:
        for item in items:
            yield item, work(item)
        return
    from concurrent.futures import ProcessPoolExecutor, as_completed

    with terminate_as_interrupt():
        others = set(multiprocessing.active_children())
        pool = ProcessPoolExecutor(max_workers=count, initializer=_worker_start, initargs=(os.getpid(), count))
        try:
            futures = {pool.submit(_run_group, work, group): group for group in _groups(items, count)}
            for future in as_completed(futures):
                yield from zip(futures[future], future.result())
        finally:
            for process in set(multiprocessing.active_children()) - others:  # the pool's workers
                process.terminate()  # a half-written take dies with its worker; its partial file is removed
            pool.shutdown(wait=True, cancel_futures=True)


def _groups(jobs: list[T], workers: int) -> list[list[T]]:
    """The jobs in groups, each sent to a worker at once: up to 8 takes, for the parent to handle
    a message per group, not per take (over thousands of small takes that was a tenth of the
    run's time), and at most a 1/16th of each worker's share, so that the workers finish close
    together."""
    size = max(1, min(8, len(jobs) // (16 * workers)))
    return [jobs[i : i + size] for i in range(0, len(jobs), size)]


def _run_group(work: Callable[[T], R], items: list[T]) -> list[R]:
    return [work(item) for item in items]


def _worker_start(parent: int, processes: int) -> None:
    """In each worker: Ctrl-C is the parent's to handle (it stops the workers), a worker
    whose parent is gone (killed outright) ends instead of running on alone, and its C
    calls take its share of the cores, not every core."""
    share_cores(processes)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)  # not the parent's handler, which a fork copies

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(1.0)
        os._exit(1)

    threading.Thread(target=watch, daemon=True).start()


def _run_dask(items: list[T], work: Callable[[T], R], workers: int, scheduler: str | None) -> Generator[tuple[T, R]]:
    try:
        from dask.distributed import Client, LocalCluster, as_completed
    except ImportError:
        raise RuntimeError('Dask is not installed: pip install "motiontheater[dask]"') from None
    processes = workers or cpu_count()
    cluster = (
        None
        if scheduler
        else LocalCluster(n_workers=processes, threads_per_worker=1, processes=True, dashboard_address=None)
    )
    client = Client(scheduler or cluster)
    try:
        if cluster is not None:  # a local cluster's workers share this machine's cores (a scheduler's may be anywhere)
            client.run(share_cores, processes)
        futures = client.map(work, items, pure=False)
        item_of = {future.key: item for future, item in zip(futures, items)}
        for future in as_completed(futures):
            yield item_of[future.key], future.result()
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def report_json(summary: Summary) -> str:
    """The summary and every take's result as JSON text."""
    data = summary.as_dict()
    data["results"] = [asdict(r) for r in summary.results]
    return json.dumps(data, indent=2)
