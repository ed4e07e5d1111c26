"""The ``batch`` verb: a filter or a recipe over whole capture databases."""

from __future__ import annotations

import argparse
import os
import sys

from ..editing.filtering import FILTERS
from ..editing.pipeline import Pipeline
from .steps import RECIPE_HELP, add_filter_options, filter_pipeline
from .takes import add_nan_option, add_take_options
from .verb import Verb, prose


def _arguments(parser: argparse.ArgumentParser) -> None:
    add_filter_options(parser)
    parser.add_argument(
        "--recipe",
        metavar="FILE",
        help="a TOML recipe of steps (instead of a filter flag), or a folder of recipes, one per take, as check "
        "--recipes writes them (TAKE.toml, the inputs' tree below it): each take runs its own, a take with none "
        "is left out",
    )
    parser.add_argument("inputs", nargs="+", help="AMC and BVH files, folders or globs")
    parser.add_argument("-o", "--output", required=True, help="the output folder")
    add_take_options(parser)
    parser.add_argument("--jobs", type=int, default=0, help="processes (default: every core)")
    parser.add_argument(
        "--resume",
        action="store_true",
        help="skip takes already done by this recipe from inputs unchanged since (the output folder's manifest says)",
    )
    parser.add_argument(
        "--in-place",
        action="store_true",
        help="allow outputs to replace their inputs, and skeletons to replace other skeleton files beside them",
    )
    add_nan_option(parser)
    parser.add_argument("--quiet", action="store_true", help="no progress bar or summary (failures still reported)")
    parser.add_argument("--json", action="store_true", help="print a JSON summary")
    parser.add_argument("--dask", action="store_true", help="run on a local Dask cluster of --jobs workers")
    parser.add_argument("--scheduler", help="run on the Dask cluster at this address (tcp://HOST:PORT)")
    parser.add_argument(
        "--stream-above",
        type=float,
        default=256.0,
        metavar="MB",
        help="stream takes larger than this many MB in chunks (default 256)",
    )


def _batch(args: argparse.Namespace) -> int:
    from ..databases.batch import Progress, plan_jobs, report_json, run

    has_filter = any(getattr(args, kind) is not None for kind in FILTERS)
    if bool(args.recipe) == has_filter:
        raise ValueError("give a recipe (--recipe FILE) or one filter (--median N, --mean N or --binomial N)")
    recipes = args.recipe if args.recipe and os.path.isdir(args.recipe) else None
    pipeline = None if recipes else Pipeline.read(args.recipe) if args.recipe else filter_pipeline(args)
    # the takes are read by the workers: the take options go with each job
    jobs, settled = plan_jobs(
        args.inputs,
        args.output,
        pipeline,
        recipes=recipes,
        skeleton=args.asf,
        frame_rate=args.frame_rate,
        unit=args.unit,
        body=args.body,
        allow_nan=args.allow_nan,
        resume=args.resume,
        in_place=args.in_place,
        stream_above=int(args.stream_above * 1e6),
    )
    progress = Progress(len(jobs), sum(j.bytes for j in jobs), enabled=False if args.quiet or args.json else None)
    summary = run(
        jobs,
        settled,
        workers=args.jobs,
        scheduler=args.scheduler,
        dask_local=args.dask,
        progress=progress,
        out=args.output,
    )
    if args.json:
        print(report_json(summary))
    elif not args.quiet or summary.failed or summary.stopped or summary.interrupted:
        trouble = summary.failed or summary.stopped or summary.interrupted
        print(summary.text(), file=sys.stderr if trouble else sys.stdout)
    if summary.interrupted:
        return 130
    return 1 if summary.failed or summary.stopped else 0


BATCH = Verb(
    "batch",
    "apply a filter or a recipe to whole capture databases: folders, globs, all cores or a Dask cluster",
    _arguments,
    _batch,
    description=prose(
        "Apply a filter (--median N, --mean N, --binomial N) or a recipe of steps (--recipe FILE) to "
        "every AMC and BVH take under the inputs (files, folders searched recursively, globs), writing "
        "into an output folder that mirrors the input tree (several input folders: a subfolder each, named as the folder), with each take's skeleton found by the "
        "CMU/HDM05 naming (or --asf). Runs on all cores (--jobs), or on a Dask cluster (--dask for a "
        "local one, --scheduler tcp://HOST:PORT). Each output is written under a temporary name and "
        "renamed when complete; --resume skips takes already done; a bad take is reported and the "
        "others go on; the exit status is 1 when any take failed. Takes above --stream-above MB are "
        "streamed in chunks when the recipe is a single filter."
    )
    + RECIPE_HELP,
    epilog="Example: motiontheater batch --median 5 --jobs 2 captures/ -o smoothed/\n"
    "Example: motiontheater batch --recipe steps.toml captures/ -o cleaned/\n"
    "Example: motiontheater check captures/ --recipes fixes/ && motiontheater batch --recipe fixes/ captures/ -o fixed/",
    laid_out=True,
)
