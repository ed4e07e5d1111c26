"""Checking a whole database: every take under the inputs on all cores (or a Dask cluster), with
progress; what each take's check found, the curve of each finding's worst channel for a
report's plot, and the fix recipes written beside them."""

from __future__ import annotations

import os
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from mtcore import cpu_count

from .._io import output
from ..formats.amc import open_amc
from ..formats.cut import Cut
from ..formats.table import format_of, read_skeleton, read_take_frames, skeleton_for
from ..model.errors import FormatError
from ..model.motion import Motion
from ..model.rig import choose_body
from .batch import Progress, find_takes, run_each
from .check import check_blocks, check_motion, header_finding, recipe
from .findings import Finding

STREAM_ABOVE = 16 << 20
"""Bytes of AMC above which a take is checked a piece at a time as it is read (its frames never
held at once): the check's memory does not grow with the take."""
READ_BYTES = 8 << 20
"""Bytes of text such a take is read at a time."""
READ_TOGETHER = 8
"""Takes a worker reads before it checks them (:func:`check_group`): 7% less time than reading
and checking in turn over the 44 AMC takes of the corpus, in one process."""
CURVE_POINTS = 200
"""The most samples of a finding's plot: longer stretches are decimated."""
CURVE_SECONDS = 0.5
"""Seconds of the take shown on either side of a finding."""


@dataclass(frozen=True)
class Curve:
    """A finding's worst channel around it: frame numbers and values in ``unit`` (deg or m)."""

    frames: tuple[int, ...]
    values: tuple[float | None, ...]
    unit: str


@dataclass(frozen=True)
class TakeCheck:
    """One take's check: its findings (a take that could not be read has one, of kind
    "unreadable"), a curve per finding (None where it has no channel), and what was read."""

    take: str
    relative: str
    findings: tuple[Finding, ...]
    curves: tuple[Curve | None, ...] = ()
    frames: int = 0
    frame_rate: float = 0.0
    bytes: int = 0
    first_frame: int = 1
    view: str | None = None

    @property
    def fixable(self) -> tuple[Finding, ...]:
        """The findings a recipe fixes."""
        return tuple(f for f in self.findings if f.fix and f.severity != "low")


@dataclass(frozen=True)
class CheckJob:
    """What a worker needs to check a take."""

    take: str
    relative: str
    asf: str | None = None
    frame_rate: float | None = None
    unit: str | None = None
    bytes: int = 0
    views: str | None = None  # a folder for the viewer page of a take with medium or high findings
    curves: bool = False  # the curve of each finding, for a report's plots
    body: str | None = None  # the joint that carries the body, where the take's own is not it


def check_job(job: CheckJob) -> TakeCheck:
    """Read and check one take; a take that cannot be read is one finding that says why.  An AMC
    take larger than STREAM_ABOVE is read a piece at a time as it is checked, so that memory does
    not grow with the take (its findings then have no curves and it gets no viewer page)."""
    return check_group([job])[0]


def check_group(jobs: list[CheckJob]) -> list[TakeCheck]:
    """:func:`check_job` of each job, every take read before the first is checked (a group of
    :func:`reading_groups`): reading and checking in turn, take by take, leaves each to begin
    with the caches full of the other's work."""
    read = [_read(job) for job in jobs]
    return [found if isinstance(found, TakeCheck) else _checked(job, *found) for job, found in zip(jobs, read)]


def reading_groups(jobs: list[CheckJob], workers: int = 1) -> list[list[CheckJob]]:
    """The jobs in order, in groups read together: up to READ_TOGETHER takes of at most
    STREAM_ABOVE bytes in all (a larger take alone), so that a group's frames stay few; and so
    many groups that each of ``workers`` processes gets four or more (a few takes on many
    cores are not left to one)."""
    most = max(1, min(READ_TOGETHER, len(jobs) // (4 * max(workers, 1))))
    groups: list[list[CheckJob]] = []
    size = 0
    for job in jobs:
        if groups and len(groups[-1]) < most and size + job.bytes <= STREAM_ABOVE:
            groups[-1].append(job)
            size += job.bytes
        else:
            groups.append([job])
            size = job.bytes
    return groups


def _read(job: CheckJob) -> TakeCheck | tuple[Motion, Cut | None]:
    """The take and how its file disagrees with its header; its whole check where it is read a
    piece at a time, or the finding that it cannot be read."""
    try:
        if job.bytes > STREAM_ABOVE and format_of(job.take).suffix == ".amc":
            return _streamed(job)
        # looked at, not written back: the text's layout is not read
        return read_take_frames(job.take, job.asf, job.frame_rate, job.unit, workers=1, layout=False)
    except (FormatError, ValueError, OSError, MemoryError) as e:
        return _unreadable(job, e)


def _checked(job: CheckJob, motion: Motion, cut: Cut | None) -> TakeCheck:
    if job.body is not None:  # a joint the take lacks is the caller's mistake: it stops the run
        motion = choose_body(motion, job.body)
    findings = tuple(check_motion(motion, job.take))
    if cut is not None:
        findings = (header_finding(motion, cut, job.take), *findings)
    curves = tuple(_curve(motion, f) for f in findings) if job.curves else ()
    view = None
    if job.views is not None and any(f.severity != "low" for f in findings):
        from ..views.viewer import write_page

        view = os.fspath(Path(job.views) / (job.relative + ".html"))
        write_page([motion], view, names=[job.relative])
    return TakeCheck(
        job.take, job.relative, findings, curves, motion.frames, motion.frame_rate, job.bytes, motion.first_frame, view
    )


def _unreadable(job: CheckJob, e: Exception) -> TakeCheck:
    reason = str(e) if job.take in str(e) else f"{job.take}: {e}"
    unreadable = Finding(job.take, "unreadable", (), 0, -1, "high", 0.0, "", reason)
    return TakeCheck(job.take, job.relative, (unreadable,), (None,), bytes=job.bytes)


def _streamed(job: CheckJob) -> TakeCheck:
    """Check an AMC take read a piece at a time (:func:`~motiontheater.formats.amc.open_amc`)."""
    companion = skeleton_for(job.take, job.asf)
    assert companion is not None  # an AMC's
    take = open_amc(job.take, read_skeleton(companion, job.unit), job.frame_rate, read_bytes=READ_BYTES)
    template = take.motion if job.body is None else choose_body(take.motion, job.body)
    frames = 0

    def counted() -> Iterator[np.ndarray]:
        nonlocal frames
        for values in take.pieces():
            frames += len(values)
            yield values

    findings = tuple(check_blocks(template, counted(), job.take))
    if not frames:
        raise ValueError(f"{job.take}: the take holds no frames")
    curves = (None,) * len(findings) if job.curves else ()
    return TakeCheck(
        job.take, job.relative, findings, curves, frames, template.frame_rate, job.bytes, template.first_frame
    )


def _curve(motion, finding: Finding) -> Curve | None:
    if finding.channel is None:
        return None
    joint, dof = finding.channel.rsplit(" ", 1)
    column = motion.columns(joint, dof)[0]
    pad = round(CURVE_SECONDS * motion.frame_rate)
    first = max(finding.first - pad, motion.first_frame) - motion.first_frame
    last = min(finding.last + pad, motion.last_frame) - motion.first_frame
    step = max(1, -(-(last - first + 1) // CURVE_POINTS))
    rows = np.arange(first, last + 1, step)
    values = motion.values[rows, column]
    skeleton = motion.skeleton
    if dof.startswith("r"):
        values = np.degrees(values) if skeleton.angle_unit == "rad" else values
        unit = "deg"
    else:
        values = values * skeleton.meters_per_unit
        unit = "m"
    shown = np.round(values, 6).tolist()
    if not np.isfinite(values).all():
        shown = [v if np.isfinite(v) else None for v in shown]
    return Curve(tuple((rows + motion.first_frame).tolist()), tuple(shown), unit)


def plan(
    inputs: Iterable[str],
    *,
    asf: str | None = None,
    frame_rate: float | None = None,
    unit: str | None = None,
    views: str | os.PathLike | None = None,
    curves: bool = False,
    body: str | None = None,
) -> list[CheckJob]:
    """A job per AMC and BVH take under the inputs (files, folders searched recursively, globs);
    ``views``: the folder where each take with medium or high findings gets its viewer page;
    ``curves``: keep each finding's curve (for an HTML report's plots).  An AMC's skeleton is
    found here, each folder listed once (a database holds thousands of takes in a few folders)."""
    jobs = []
    folders: dict[Path, list[Path]] = {}
    for take, relative in find_takes(inputs):
        try:
            size = os.stat(take).st_size
        except OSError:
            size = 0
        try:
            companion = skeleton_for(take, asf, folders)
        except OSError:  # the take's check says what is missing
            companion = None
        folder = None if views is None else os.fspath(views)
        skeleton = None if companion is None else os.fspath(companion)
        jobs.append(
            CheckJob(os.fspath(take), relative.as_posix(), skeleton, frame_rate, unit, size, folder, curves, body)
        )
    return jobs


def survey(
    jobs: list[CheckJob],
    *,
    workers: int = 0,
    scheduler: str | None = None,
    dask_local: bool = False,
    progress: Progress | None = None,
) -> list[TakeCheck]:
    """Every job's check, in the order of the jobs, on ``workers`` processes (0: every core),
    the Dask cluster at ``scheduler`` or a local one, with ``progress`` advanced take by take."""
    progress = progress or Progress(len(jobs), sum(j.bytes for j in jobs), enabled=False)
    done: dict[str, TakeCheck] = {}
    processes = 1 if scheduler or dask_local else workers or cpu_count()  # a cluster's size is its own
    groups = reading_groups(jobs, processes)
    results = run_each(groups, check_group, workers, scheduler=scheduler, dask_local=dask_local)
    try:
        for group, checks in results:
            for job, result in zip(group, checks):
                done[job.take] = result
                progress.advance(result)  # type: ignore[arg-type]
    finally:
        results.close()
        progress.close()
    return [done[job.take] for job in jobs]


@dataclass
class Written:
    """Where the recipes went: the take of each and its recipe file."""

    recipes: list[tuple[str, str]] = field(default_factory=list)


def recipe_text(check: TakeCheck) -> str:
    """The recipe that fixes a take's medium and high findings, with a comment line per finding."""
    lines = [f"# motiontheater check: the steps that fix {check.take}", "# run: motiontheater apply TAKE --recipe THIS"]
    for f in check.fixable:
        joints = ", ".join(f.joints) or "every joint"
        lines.append(f"# frames {f.first}-{f.last}, {joints}: {f.severity} {f.kind}, {f.size:g} {f.unit}: {f.detail}")
    return "\n".join(lines) + "\n\n" + recipe(check.fixable).to_toml()


def write_recipes(checks: Iterable[TakeCheck], folder: str | os.PathLike) -> Written:
    """A recipe per take with findings to fix, at the take's path below ``folder`` with .toml
    added (01_01.amc.toml: a folder may hold 01_01.amc and 01_01.bvh)."""
    written = Written()
    for check in checks:
        if not check.fixable:
            continue
        target = Path(folder) / (check.relative + ".toml")
        with output(target) as f:
            f.write(recipe_text(check).encode("utf-8"))
        written.recipes.append((check.take, os.fspath(target)))
    return written
