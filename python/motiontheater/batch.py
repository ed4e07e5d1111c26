"""Batch processing of capture databases: many takes, all cores or a Dask cluster, bounded memory.

A recipe (a filter, for now) is applied to every AMC found under the inputs
(files, folders searched recursively, globs); results go to an output folder
that mirrors the input tree, each written to a temporary name and renamed
when complete.  A take larger than a threshold is streamed in chunks of
frames, so memory does not grow with its length, to the same bytes as
processing it whole.
"""

from __future__ import annotations

import functools
import glob
import itertools
import json
import os
import shutil
import signal
import sys
import time
from collections.abc import Callable, Iterable
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from mtcore import format_frames, scan_frames
from mtcore.errors import FormatError, SequenceError

from ._io import PARTIAL_PREFIX, encode, output
from .amc import (
    _first_frame_order,
    _header_lines,
    _layout,
    _read_header,
    _write_order,
    read_amc,
    skeleton_path_for,
    write_amc,
)
from .asf import read_asf
from .bvh import read_bvh, write_bvh
from .filtering import Smoother, TakeStats
from .motion import Motion

STREAM_ABOVE = 256 << 20  # bytes of AMC above which a take is streamed
CHUNK_FRAMES = 1 << 15  # frames per streamed chunk (a multiple of the filters' block length)
READ_BYTES = 8 << 20


@dataclass(frozen=True)
class Recipe:
    """What to do to every take: a filter as ``motiontheater filter`` takes it."""

    kind: str
    size: int
    joints: tuple[str, ...] | None = None
    translation: bool = True
    mode: str = "nearest"

    def smoother(self, skeleton, workers: int | None = 1) -> Smoother:
        return Smoother(
            skeleton, self.kind, self.size, self.joints, translation=self.translation, mode=self.mode, workers=workers
        )


@dataclass(frozen=True)
class Job:
    input: str
    output: str
    skeleton: str
    recipe: Recipe
    frame_rate: float | None = None
    stream_above: int = STREAM_ABOVE
    chunk_frames: int = CHUNK_FRAMES


@dataclass
class Result:
    input: str
    output: str
    ok: bool = True
    skipped: bool = False
    streamed: bool = False
    error: str = ""
    bytes: int = 0
    frames: int = 0
    seconds: float = 0.0


TAKES = (".amc", ".bvh")


def find_takes(inputs: Iterable[str]) -> list[tuple[Path, Path]]:
    """(take, its path relative to the output folder) for every AMC and BVH under the inputs."""
    found: dict[Path, Path] = {}
    for item in inputs:
        wild = next((i for i, c in enumerate(item) if c in "*?["), None)
        if wild is not None:
            # outputs mirror the tree below the folder the pattern starts in
            prefix = item[:wild]
            base = Path(prefix) if prefix.endswith(os.sep) else Path(prefix).parent
            for match in sorted(glob.glob(item, recursive=True)):
                if match.lower().endswith(TAKES):
                    found.setdefault(Path(match), Path(match).relative_to(base))
        elif os.path.isdir(item):
            for path in sorted(Path(item).rglob("*")):
                if path.suffix.lower() in TAKES and path.is_file():
                    found.setdefault(path, path.relative_to(item))
        elif os.path.isfile(item):
            found.setdefault(Path(item), Path(Path(item).name))
        else:
            raise FileNotFoundError(f"no file, folder or glob match: {item}")
    return list(found.items())


def plan_jobs(
    inputs: Iterable[str],
    out: str | os.PathLike,
    recipe: Recipe,
    *,
    skeleton: str | None = None,
    frame_rate: float | None = None,
    resume: bool = False,
    stream_above: int = STREAM_ABOVE,
    chunk_frames: int = CHUNK_FRAMES,
) -> tuple[list[Job], list[Result]]:
    """The jobs to run, and the takes skipped or failed before running (no skeleton, already done)."""
    jobs, settled = [], []
    for take, relative in find_takes(inputs):
        target = Path(out) / relative
        try:
            asf = None if take.suffix.lower() == ".bvh" else Path(skeleton) if skeleton else skeleton_path_for(take)
        except FileNotFoundError as e:
            settled.append(Result(str(take), str(target), ok=False, error=str(e)))
            continue
        inputs_time = max(take.stat().st_mtime, asf.stat().st_mtime if asf else 0)
        if resume and target.exists() and target.stat().st_mtime >= inputs_time:
            settled.append(Result(str(take), str(target), skipped=True, bytes=take.stat().st_size))
            continue
        jobs.append(
            Job(str(take), str(target), str(asf) if asf else "", recipe, frame_rate, stream_above, chunk_frames)
        )
    return jobs, settled


def run_job(job: Job) -> Result:
    """Process one take; every failure becomes a Result naming the file, line and reason."""
    start = time.perf_counter()
    result = Result(job.input, job.output, bytes=os.path.getsize(job.input))
    try:
        os.makedirs(os.path.dirname(job.output) or ".", exist_ok=True)
        if not job.skeleton:  # a BVH take holds its skeleton
            motion = read_bvh(job.input)
            write_bvh(_smooth(motion, job.recipe), job.output)
            result.frames = motion.frames
            result.seconds = time.perf_counter() - start
            return result
        skeleton = _skeleton(job.skeleton, *_stamp(job.skeleton))
        _copy_skeleton(job.skeleton, os.path.dirname(job.output))
        if result.bytes > job.stream_above:
            result.frames = stream_filter(job.input, job.output, skeleton, job.recipe, job.frame_rate, job.chunk_frames)
            result.streamed = True
        else:
            motion = read_amc(job.input, skeleton, job.frame_rate, workers=1)
            write_amc(_smooth(motion, job.recipe), job.output)
            result.frames = motion.frames
    except (FormatError, ValueError, OSError) as e:
        result.ok, result.error = False, str(e)
    result.seconds = time.perf_counter() - start
    return result


def _smooth(motion: Motion, recipe: Recipe) -> Motion:
    return motion.filter(
        recipe.kind, recipe.size, recipe.joints, translation=recipe.translation, mode=recipe.mode, workers=1
    )


def _stamp(path: str) -> tuple[int, int]:
    status = os.stat(path)
    return status.st_mtime_ns, status.st_size


@functools.lru_cache(maxsize=256)
def _skeleton(path: str, mtime_ns: int, size: int):
    """A worker reads each skeleton once (a database has a few, and thousands of takes);
    a changed file has a new stamp and is read again."""
    return read_asf(path)


def _copy_skeleton(asf: str, folder: str) -> None:
    """The skeleton beside the outputs that use it, so that the output folder stands alone."""
    target = os.path.join(folder, os.path.basename(asf))
    if os.path.abspath(target) != os.path.abspath(asf) and not os.path.exists(target):
        with open(asf, "rb") as src, output(target) as dst:
            shutil.copyfileobj(src, dst)


def _frames_of(path: str, skeleton, keys, offsets, counts, frame_rate):
    """(header, line order, rate) and an iterator of (first frame number, values) pieces of a take,
    read READ_BYTES at a time and cut at frame lines."""
    with open(path, "rb") as f:
        head = f.read(READ_BYTES)
    header, body, header_lines, rate = _read_header(head, path, skeleton, frame_rate)
    order = _first_frame_order(head, body, set(skeleton.joint_names))

    def pieces():
        """Each call reads the take again from its first frame."""
        pending, lines_done = b"", header_lines
        with open(path, "rb") as f:
            f.seek(body)
            while True:
                more = f.read(READ_BYTES)
                text = pending + more
                if more:
                    cut = max(text.rfind(b"\n", 0, len(text) - 1), text.rfind(b"\r", 0, len(text) - 1))
                    # back to the start of the last frame line, so that no frame is split
                    cut = _last_frame_start(text, cut)
                    if cut <= 0:
                        pending = text
                        continue
                    piece, pending = text[:cut], text[cut:]
                else:
                    piece, pending = text, b""
                try:
                    values, first = scan_frames(
                        piece, keys, offsets, counts, len(skeleton.channels), noun="bone", workers=1
                    )
                except FormatError as e:
                    raise e.at(path, lines_done) from None
                if len(values):
                    yield first, values, lines_done
                lines_done += piece.count(b"\n") + piece.count(b"\r") - piece.count(b"\r\n")
                if not more:
                    return

    return header, order, rate, pieces


def _last_frame_start(text: bytes, limit: int) -> int:
    """The offset of the last line, before ``limit``, that holds only a frame number, or 0."""
    end = limit
    while end > 0:
        start = max(text.rfind(b"\n", 0, end), text.rfind(b"\r", 0, end)) + 1
        if text[start:end].strip().isdigit():
            return start
        end = start - 1
    return 0


def stream_filter(
    path: str, target: str, skeleton, recipe: Recipe, frame_rate: float | None = None, chunk_frames: int = CHUNK_FRAMES
) -> int:
    """Filter a take of any length in chunks of frames; the same bytes as filtering it whole.

    Two passes over the file: the first gathers what smoothing needs of the
    whole take (channel ranges, first frame), the second unwraps, smooths
    and writes chunk by chunk, each smoothed with a halo of neighbouring
    frames and aligned to the filters' blocks.  Returns the frame count.
    """
    smoother = recipe.smoother(skeleton)
    keys, offsets, counts = _layout(skeleton, skeleton.joint_names)
    header, order, rate, pieces = _frames_of(path, skeleton, keys, offsets, counts, frame_rate)
    stats, frames, first_frame = None, 0, None
    for first, values, lines in pieces():
        if first_frame is None:
            first_frame = first
        elif first != first_frame + frames:
            raise SequenceError(
                f"frame number {first} out of sequence: expected {first_frame + frames}", lines + 1, path
            )
        if stats is None:
            stats = TakeStats.of(values)
        else:
            stats.update(values)
        frames += len(values)
    header_motion = Motion(
        skeleton,
        np.zeros((0, len(skeleton.channels))),
        rate,
        first_frame or 1,
        tuple(text for _, text in header),
        order,
    )
    write_keys, write_offsets, write_counts = _layout(skeleton, _write_order(skeleton, order))
    block = smoother.block
    chunk = max(block, chunk_frames // block * block)
    lead = -(-smoother.halo // block) * block  # frames before a chunk: the halo, rounded up to a block

    with output(target) as f:
        f.write(encode("".join(line + "\n" for line in _header_lines(header_motion))))
        if not frames:
            return 0
        unwrapped = _unwrapped_chunks(pieces, smoother, chunk)
        tail = np.zeros((0, len(skeleton.channels)))  # unwrapped frames before the current chunk
        current = next(unwrapped)
        start = 0
        for following in itertools.chain(unwrapped, [None]):  # one chunk of lookahead, no more
            after = following[: smoother.halo] if following is not None else tail[:0]
            buffer = np.concatenate([tail[len(tail) - min(lead, start) :], current, after])
            before = min(lead, start)
            smoothed = smoother.smooth(buffer, stats)[before : before + len(current)]
            format_frames(smoothed, first_frame + start, write_keys, write_offsets, write_counts, f.write)
            tail = np.concatenate([tail, current])[-lead:] if lead else tail
            start += len(current)
            current = following
            if current is None:
                break
    return frames


def _unwrapped_chunks(pieces: Callable, smoother: Smoother, chunk: int):
    """The take's frames, unwrapped, in chunks of exactly ``chunk`` frames (the last shorter)."""
    previous, turns, pending = None, None, []
    held = 0
    for _, values, _ in pieces():
        unwrapped, turns = smoother.unwrap(values, previous, turns)
        previous = values[-1]
        pending.append(unwrapped)
        held += len(unwrapped)
        while held >= chunk:
            joined = np.concatenate(pending)
            yield joined[:chunk]
            pending, held = [joined[chunk:]], held - chunk
    if held:
        yield np.concatenate(pending)


class Progress:
    """A one-line progress bar on stderr (files and MB, rate, ETA); silent unless stderr is a terminal."""

    def __init__(self, files: int, total_bytes: int, enabled: bool | None = None):
        self.files, self.total = files, total_bytes
        self.done_files, self.done_bytes = 0, 0
        self.start = time.perf_counter()
        self.enabled = sys.stderr.isatty() if enabled is None else enabled

    def advance(self, result: Result) -> None:
        self.done_files += 1
        self.done_bytes += result.bytes
        if not self.enabled:
            return
        elapsed = max(time.perf_counter() - self.start, 1e-9)
        rate = self.done_bytes / elapsed
        eta = (self.total - self.done_bytes) / rate if rate else 0
        width = 24
        filled = int(width * self.done_bytes / max(self.total, 1))
        sys.stderr.write(
            f"\r[{'=' * filled}{' ' * (width - filled)}] {self.done_files}/{self.files} files, "
            f"{self.done_bytes / 1e6:.1f}/{self.total / 1e6:.1f} MB, {rate / 1e6:.1f} MB/s, "
            f"ETA {eta:.0f} s "
        )
        sys.stderr.flush()

    def close(self) -> None:
        if self.enabled:
            sys.stderr.write("\n")


@dataclass
class Summary:
    results: list[Result] = field(default_factory=list)
    seconds: float = 0.0

    @property
    def failed(self) -> list[Result]:
        return [r for r in self.results if not r.ok]

    def as_dict(self) -> dict:
        done = [r for r in self.results if r.ok and not r.skipped]
        processed = sum(r.bytes for r in done)
        return {
            "files": len(self.results),
            "processed": len(done),
            "skipped": sum(r.skipped for r in self.results),
            "failed": len(self.failed),
            "streamed": sum(r.streamed for r in self.results),
            "megabytes": processed / 1e6,
            "seconds": self.seconds,
            "megabytes_per_second": processed / 1e6 / self.seconds if self.seconds else 0.0,
            "failures": [{"file": r.input, "error": r.error} for r in self.failed],
        }

    def text(self) -> str:
        d = self.as_dict()
        lines = [
            f"{d['processed']} processed, {d['skipped']} skipped (already done), {d['failed']} failed "
            f"of {d['files']} takes; {d['megabytes']:.1f} MB in {d['seconds']:.1f} s "
            f"({d['megabytes_per_second']:.1f} MB/s)"
        ]
        lines += [
            f"FAILED {f['error']}" if f["file"] in f["error"] else f"FAILED {f['file']}: {f['error']}"
            for f in d["failures"]
        ]
        return "\n".join(lines)


def remove_partials(folder: str | os.PathLike) -> int:
    """Delete the temporary files a killed run left in the output folder; returns how many."""
    removed = 0
    for path in Path(folder).rglob(PARTIAL_PREFIX + "*") if Path(folder).is_dir() else ():
        path.unlink(missing_ok=True)
        removed += 1
    return removed


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
    ``scheduler``, or a local Dask cluster; the summary lists every take's result."""
    summary = Summary(list(settled))
    progress = progress or Progress(len(jobs), sum(os.path.getsize(j.input) for j in jobs), enabled=False)
    start = time.perf_counter()
    remove_partials(out)
    try:
        if scheduler or dask_local:
            results = _run_dask(jobs, workers, scheduler)
        else:
            results = _run_local(jobs, workers)
        for result in results:
            summary.results.append(result)
            progress.advance(result)
    finally:
        progress.close()
        remove_partials(out)
    summary.seconds = time.perf_counter() - start
    return summary


def _run_local(jobs: list[Job], workers: int):
    count = workers or os.cpu_count() or 1
    if count == 1 or len(jobs) <= 1:
        yield from (run_job(job) for job in jobs)
        return
    from concurrent.futures import ProcessPoolExecutor, as_completed

    previous = signal.signal(signal.SIGTERM, _interrupt)
    pool = ProcessPoolExecutor(max_workers=count)
    try:
        futures = [pool.submit(run_job, job) for job in jobs]
        for future in as_completed(futures):
            yield future.result()
    except BaseException:
        for process in list(getattr(pool, "_processes", {}).values()):
            process.terminate()  # a half-written take dies with its worker; its partial file is removed
        raise
    finally:
        pool.shutdown(wait=True, cancel_futures=True)
        signal.signal(signal.SIGTERM, previous)


def _interrupt(signum, frame):
    raise KeyboardInterrupt(f"signal {signum}")


def _run_dask(jobs: list[Job], workers: int, scheduler: str | None):
    try:
        from dask.distributed import Client, LocalCluster, as_completed
    except ImportError:
        raise RuntimeError('Dask is not installed: pip install "motiontheater[dask]"') from None
    cluster = (
        None
        if scheduler
        else LocalCluster(
            n_workers=workers or os.cpu_count() or 1, threads_per_worker=1, processes=True, dashboard_address=None
        )
    )
    client = Client(scheduler or cluster)
    try:
        futures = client.map(run_job, jobs, pure=False)
        for future in as_completed(futures):
            yield future.result()
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def report_json(summary: Summary) -> str:
    data = summary.as_dict()
    data["results"] = [asdict(r) for r in summary.results]
    return json.dumps(data, indent=2)
