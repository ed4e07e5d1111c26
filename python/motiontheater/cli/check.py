"""The ``check`` verb: what is wrong with each take of a database, where, and the recipes that fix it."""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

from ..databases.findings import KINDS, SEVERITIES
from .takes import add_take_options
from .verb import Verb

LISTED = 8
"""Findings listed per take in the text summary; the report and --json hold every one."""


def _arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("inputs", nargs="+", metavar="INPUT", help="AMC and BVH files, folders or globs")
    parser.add_argument(
        "-o", "--output", metavar="REPORT", help="write the report: .html (a page to open), .json or .csv"
    )
    parser.add_argument("--json", action="store_true", help="print every finding as JSON (a list of objects)")
    parser.add_argument(
        "--recipes", metavar="FOLDER", help="write a recipe that fixes each take (TAKE.toml, the inputs' tree below it)"
    )
    parser.add_argument(
        "--severity",
        choices=SEVERITIES,
        default="low",
        help="the least severity listed (default: low, every finding); recipes fix medium and high ones",
    )
    parser.add_argument("--jobs", type=int, default=0, help="processes (default: every core)")
    parser.add_argument("--dask", action="store_true", help="run on a local Dask cluster of --jobs workers")
    parser.add_argument("--scheduler", help="run on the Dask cluster at this address (tcp://HOST:PORT)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar and no listing, only the last line")
    add_take_options(parser)


def _check(args: argparse.Namespace) -> int:
    from ..databases.batch import Progress
    from ..databases.report import REPORT_SUFFIXES, json_text, write_report
    from ..databases.survey import plan, survey, write_recipes

    report = args.output
    if report is not None and Path(report).suffix.lower() not in REPORT_SUFFIXES:
        raise ValueError(f"{report}: the report is written as {', '.join(REPORT_SUFFIXES)}; name it so")
    views = None
    if report is not None and Path(report).suffix.lower() == ".html":
        views = Path(report).with_name(Path(report).stem + "_views")
    jobs = plan(
        args.inputs,
        asf=args.asf,
        frame_rate=args.frame_rate,
        unit=args.unit,
        views=views,
        curves=bool(views),
        body=args.body,
    )
    if not jobs:
        raise ValueError(f"no AMC or BVH take under {' '.join(args.inputs)}")
    start = time.perf_counter()
    progress = Progress(len(jobs), sum(j.bytes for j in jobs), enabled=None if not (args.quiet or args.json) else False)
    checks = survey(jobs, workers=args.jobs, scheduler=args.scheduler, dask_local=args.dask, progress=progress)
    seconds = time.perf_counter() - start
    wrote = []
    if report is not None:
        links = {c.take: os.path.relpath(c.view, Path(report).parent or ".") for c in checks if c.view}
        write_report(checks, report, args.severity, links)
        wrote.append(f"wrote {report}" + (f" (viewer pages in {views})" if links else ""))
    if args.recipes is not None:
        written = write_recipes(checks, args.recipes)
        count = len(written.recipes)
        wrote.append(f"{count} recipe{'s' if count != 1 else ''} in {args.recipes}" if count else "no recipe to write")
    if args.json:
        sys.stdout.write(json_text(checks, args.severity))
    elif not args.quiet:
        _listing(checks, args.severity)
    counts = {s: sum(1 for c in checks for f in c.findings if f.severity == s) for s in SEVERITIES}
    unreadable = sum(1 for c in checks for f in c.findings if f.kind == "unreadable")
    last = (
        f"check: {len(checks)} take{'s' if len(checks) != 1 else ''}"
        + (f" ({unreadable} unreadable)" if unreadable else "")
        + f" in {seconds:.1f} s: {counts['high']} high, {counts['medium']} medium, {counts['low']} low findings"
    )
    print("; ".join([last, *wrote]), file=sys.stderr if args.json else sys.stdout)
    return 0


def _listing(checks, least: str) -> None:
    floor = SEVERITIES.index(least)
    for check in checks:
        shown = sorted((f for f in check.findings if f.rank >= floor), key=lambda f: (-f.rank, f.first))
        if not shown:
            continue
        tally = ", ".join(
            f"{n} {s}" for s in reversed(SEVERITIES) if (n := sum(1 for f in check.findings if f.severity == s))
        )
        print(f"{check.take}: {tally}")
        for f in shown[:LISTED]:
            frames = (
                f"frames {f.first}-{f.last}" if f.last > f.first else f"frame {f.first}" if f.last == f.first else ""
            )
            print(f"  {f.severity:<6} {f.kind:<8} {frames:<18} {f.detail}")
        if len(shown) > LISTED:
            print(f"  and {len(shown) - LISTED} more (all of them: --json, or -o report.html)")


CHECK = Verb(
    "check",
    "find what is wrong with each take (spikes, flips, gaps, frozen channels, teleports, skating feet, units) and the recipe that fixes it",
    _arguments,
    _check,
    description=(
        "Check every AMC and BVH take under the inputs, on all cores, and list what is wrong with each: where "
        "(frames as the file numbers them, joints as it spells them), how badly (low, medium, high) and how large, "
        "in degrees, metres, m/s, seconds, Hz or % of the frames. The kinds of finding: "
        + "; ".join(f"{k}: {v}" for k, v in KINDS.items())
        + ". -o writes a report: an HTML page with a table to sort and a plot of each finding's worst channel (its "
        "links open a viewer page of the take at the finding's frame; the pages go in a folder beside the report), "
        "or the same as JSON or CSV. --recipes writes, for each take with medium or high findings that a step "
        "fixes, a recipe of those steps confined to their frames and joints; run it with "
        "'motiontheater apply TAKE --recipe TAKE.toml -o FIXED', or every take its own at once with "
        "'motiontheater batch INPUTS --recipe FOLDER -o FIXED'."
    ),
    epilog=(
        "Example: motiontheater check captures/ -o report.html --recipes fixes/\n"
        "Example: motiontheater check 01_01.amc --json"
    ),
)
