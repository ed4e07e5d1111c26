"""Batch processing of capture databases: many takes, all cores or a Dask cluster, bounded memory.

A pipeline of steps (a recipe; ``motiontheater steps`` lists them) is
applied to every AMC and BVH take found under the inputs (files, folders
searched recursively, globs); results go to an output folder that mirrors
the input tree, each written to a temporary name and renamed when complete.
A take larger than a threshold is streamed in chunks of frames when its
pipeline allows (:mod:`motiontheater.streaming`), so memory does not grow
with its length, to the same bytes as processing it whole.  This module
keeps jobs, pools, progress and reports; formats and steps live elsewhere.
"""

from __future__ import annotations

import functools
import glob
import json
import os
import shutil
import signal
import sys
import time
from collections.abc import Iterable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from ._io import PARTIAL_PREFIX, output
from .amc import read_amc
from .asf import read_asf, write_asf
from .bvh import read_bvh
from .errors import FormatError
from .formats import TAKE_SUFFIXES, skeleton_for, write_take
from .motion import Motion
from .pipeline import Pipeline
from .streaming import CHUNK_FRAMES, stream, streamable

STREAM_ABOVE = 256 << 20  # bytes of AMC above which a take is streamed (when its pipeline allows)
SUFFIXES = {"asf": ".amc", "bvh": ".bvh"}  # what a motion of each skeleton convention is written as


@dataclass(frozen=True)
class Job:
    """One take to process: where it is, where its result goes (its suffix decided when written)."""

    input: str
    output: str
    skeleton: str  # the AMC's ASF; "" for a BVH
    pipeline: Pipeline
    frame_rate: float | None = None
    stream_above: int = STREAM_ABOVE
    chunk_frames: int = CHUNK_FRAMES


@dataclass
class Result:
    """What became of one take: where it went, whether it worked, and what it cost."""

    input: str
    output: str
    ok: bool = True
    skipped: bool = False
    streamed: bool = False
    error: str = ""
    bytes: int = 0
    frames: int = 0
    seconds: float = 0.0


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
                if match.lower().endswith(TAKE_SUFFIXES):
                    found.setdefault(Path(match), Path(match).relative_to(base))
        elif os.path.isdir(item):
            for path in sorted(Path(item).rglob("*")):
                if path.suffix.lower() in TAKE_SUFFIXES and path.is_file():
                    found.setdefault(path, path.relative_to(item))
        elif os.path.isfile(item):
            found.setdefault(Path(item), Path(Path(item).name))
        else:
            raise FileNotFoundError(f"no file, folder or glob match: {item}")
    return list(found.items())


def plan_jobs(
    inputs: Iterable[str],
    out: str | os.PathLike,
    pipeline: Pipeline,
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
            asf = None if take.suffix.lower() == ".bvh" else skeleton_for(take, skeleton)
        except FileNotFoundError as e:
            settled.append(Result(str(take), str(target), ok=False, error=str(e)))
            continue
        inputs_time = max(take.stat().st_mtime, asf.stat().st_mtime if asf else 0)
        if resume and target.exists() and target.stat().st_mtime >= inputs_time:
            settled.append(Result(str(take), str(target), skipped=True, bytes=take.stat().st_size))
            continue
        job = Job(str(take), str(target), str(asf) if asf else "", pipeline, frame_rate, stream_above, chunk_frames)
        jobs.append(job)
    return jobs, settled


def run_job(job: Job) -> Result:
    """Process one take; every failure becomes a Result naming the file, line and reason."""
    start = time.perf_counter()
    result = Result(job.input, job.output, bytes=os.path.getsize(job.input))
    try:
        os.makedirs(os.path.dirname(job.output) or ".", exist_ok=True)
        if job.skeleton and result.bytes > job.stream_above and streamable(job.pipeline):
            skeleton = _skeleton(job.skeleton, *_stamp(job.skeleton))
            _copy_skeleton(job.skeleton, os.path.dirname(job.output))
            result.frames = stream(
                job.input, job.output, skeleton, job.pipeline, job.frame_rate, chunk_frames=job.chunk_frames
            )
            result.streamed = True
        else:
            motion = _read(job)
            result.output = _write(job, job.pipeline.apply(motion), motion)
            result.frames = motion.frames
    except (FormatError, ValueError, OSError) as e:
        result.ok, result.error = False, str(e)
    result.seconds = time.perf_counter() - start
    return result


def _read(job: Job) -> Motion:
    if not job.skeleton:
        return read_bvh(job.input)
    return read_amc(job.input, _skeleton(job.skeleton, *_stamp(job.skeleton)), job.frame_rate, workers=1)


def _write(job: Job, result: Motion, motion: Motion) -> str:
    """Write a take's result where the job says (an exporter's suffix, or its format's); returns the path."""
    stem = os.path.splitext(job.output)[0]
    exporter = job.pipeline.exporter
    if exporter is not None:
        chosen = dict(exporter.options).get("format")
        target = stem + (f".{chosen}" if chosen else exporter.step.suffixes[0])
        job.pipeline.write(result, target)
        return target
    target = stem + SUFFIXES[result.skeleton.convention]
    folder = os.path.dirname(target)
    if result.skeleton.convention == "asf":
        if result.skeleton is motion.skeleton and job.skeleton:
            _copy_skeleton(job.skeleton, folder)
        else:
            write_asf(result.skeleton, stem + ".asf")
    write_take(result, target)
    return target


def _stamp(path: str) -> tuple[int, int]:
    status = os.stat(path)
    return status.st_mtime_ns, status.st_size


@functools.lru_cache(maxsize=256)
def _skeleton(path: str, mtime_ns: int, size: int) -> Any:
    """A worker reads each skeleton once (a database has a few, and thousands of takes);
    a changed file has a new stamp and is read again."""
    return read_asf(path)


def _copy_skeleton(asf: str, folder: str) -> None:
    """The skeleton beside the outputs that use it, so that the output folder stands alone."""
    target = os.path.join(folder, os.path.basename(asf))
    if os.path.abspath(target) != os.path.abspath(asf) and not os.path.exists(target):
        with open(asf, "rb") as src, output(target) as dst:
            shutil.copyfileobj(src, dst)


class Progress:
    """A one-line progress bar on stderr (files and MB, rate, ETA); silent unless stderr is a terminal."""

    def __init__(self, files: int, total_bytes: int, enabled: bool | None = None):
        self.files, self.total = files, total_bytes
        self.done_files, self.done_bytes = 0, 0
        self.start = time.perf_counter()
        self.enabled = sys.stderr.isatty() if enabled is None else enabled

    def advance(self, result: Result) -> None:
        """Count a finished take and redraw the bar."""
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
        """End the bar's line."""
        if self.enabled:
            sys.stderr.write("\n")


@dataclass
class Summary:
    """Every take's result and the run's time: what the batch command reports."""

    results: list[Result] = field(default_factory=list)
    seconds: float = 0.0

    @property
    def failed(self) -> list[Result]:
        """The takes that failed."""
        return [r for r in self.results if not r.ok]

    def as_dict(self) -> dict:
        """The totals and failures, ready for JSON."""
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
        """The totals in a line, then a line per failure."""
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
    """The summary and every take's result as JSON text."""
    data = summary.as_dict()
    data["results"] = [asdict(r) for r in summary.results]
    return json.dumps(data, indent=2)
