"""The ``index`` and ``search`` verbs: a database of takes' features, and the takes that hold a
motion like a query clip."""

from __future__ import annotations

import argparse
import json
import sys
import time

from .takes import add_take_options, take_of
from .verb import Verb


def _index_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("inputs", nargs="+", metavar="INPUT", help="AMC and BVH files, folders or globs")
    parser.add_argument(
        "-o", "--output", required=True, metavar="DB", help="the database (.npz); one there is brought up to date"
    )
    parser.add_argument("--jobs", type=int, default=0, help="processes (default: every core)")
    parser.add_argument("--dask", action="store_true", help="run on a local Dask cluster of --jobs workers")
    parser.add_argument("--scheduler", help="run on the Dask cluster at this address (tcp://HOST:PORT)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar, only the last line")
    parser.add_argument("--asf", help="the AMCs' skeleton (default: the ASF beside each, by the CMU/HDM05 naming)")
    parser.add_argument("--frame-rate", type=float, metavar="HZ", help="frames per second when an AMC does not say")


def _index(args: argparse.Namespace) -> int:
    from ..databases.batch import find_takes
    from ..databases.index import build, open_or_empty

    if not args.output.lower().endswith(".npz"):
        raise ValueError(f"{args.output}: a database is written as .npz; name it so")
    if not find_takes(args.inputs):
        raise ValueError(f"no AMC or BVH take under {' '.join(args.inputs)}")
    previous = open_or_empty(args.output)
    start = time.perf_counter()
    built = build(
        args.inputs, previous, asf=args.asf, frame_rate=args.frame_rate, workers=args.jobs,
        scheduler=args.scheduler, dask_local=args.dask, progress=not args.quiet,
    )  # fmt: skip
    built.database.save(args.output)
    seconds = time.perf_counter() - start
    for take, why in built.failed:
        print(f"  not indexed: {why}", file=sys.stderr)
    db = built.database
    print(
        f"index: {len(db)} take{'s' if len(db) != 1 else ''} in {args.output} ({db.seconds() / 60:.1f} min of "
        f"capture): {len(built.indexed)} indexed, {len(built.kept)} unchanged, {len(built.dropped)} gone, "
        f"{len(built.failed)} not indexed, in {seconds:.1f} s"
    )
    return 0


def _search_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("database", metavar="DB", help="a database that 'motiontheater index' wrote")
    parser.add_argument("query", metavar="QUERY", help="the take (AMC or BVH) holding the motion to find")
    parser.add_argument("-k", type=int, default=10, help="how many takes (or frames) to list (default 10)")
    parser.add_argument(
        "--frame",
        type=int,
        metavar="N",
        help="frame search (motion matching): the frames whose feet, hips and path ahead are nearest the query's "
        "at frame N",
    )
    parser.add_argument("--json", action="store_true", help="print the hits as JSON (a list of objects)")
    parser.add_argument("--view", metavar="PAGE", help="write a viewer page of the query and the hits side by side")
    add_take_options(parser, frames=True, unit=False)


def _search(args: argparse.Namespace) -> int:
    from ..databases.features import FEATURE_RATE
    from ..databases.index import Database
    from ..databases.search import nearest_frames, search

    db = Database.load(args.database)
    query = take_of(args, args.query)
    if args.frames is not None:
        query = query.crop(*args.frames)
    if args.frame is not None and args.frames is not None:
        raise ValueError("give --frame N (frame search) or --frames A:B (a clip to find), not both")
    start = time.perf_counter()
    if args.frame is not None:
        hits = nearest_frames(db, query, args.frame, args.k)
        how = (
            f"frame search: the {len(hits)} nearest of {len(db.frames)} frames "
            f"(the database holds {FEATURE_RATE:g} a second of each take)"
        )
    else:
        found = search(db, query, args.k)
        hits = found.hits
        parts = []
        if found.total:
            which = "the index's candidates" if found.filtered else "every window"
            parts.append(f"{which}: {found.windows} of {found.total} windows, {found.warped} warped")
        if found.whole:
            parts.append(f"{found.whole} take(s) shorter than the query, each warped whole")
        how = f"{len(hits)} of {len(db)} takes, " + "; ".join(parts)
    seconds = time.perf_counter() - start
    if args.json:
        json.dump([h.as_dict() for h in hits], sys.stdout, indent=1)
        sys.stdout.write("\n")
    else:
        for rank, hit in enumerate(hits, 1):
            where = f"frame {hit.first}" if hit.first == hit.last else f"frames {hit.first}-{hit.last}"
            # an exact match differs by rounding (1e-15): it prints as 0
            print(f"{rank:3d}  {round(hit.distance, 6):10.4g}  {where:<17} {hit.take}")
    last = f"search: {how}, in {seconds * 1000:.0f} ms"
    if args.view:
        _view(args, query, hits)
        last += f"; wrote {args.view}"
    print(last, file=sys.stderr if args.json else sys.stdout)
    return 0


AHEAD = 1.5
"""Seconds of each frame search hit that the viewer page shows: the frame and what follows it."""


def _view(args: argparse.Namespace, query, hits) -> None:
    """The viewer page of the query and the hits, each from its first frame (a frame search's:
    the frame and AHEAD seconds after it), so that they play aligned."""
    from ..formats.table import read_take
    from ..views.viewer import write_page

    def piece(take, first: int, last: int):
        if args.frame is not None:
            last = min(take.last_frame, first + round(AHEAD * take.frame_rate))
        return take.crop(first, last)

    start = args.frame if args.frame is not None else query.first_frame
    takes = [piece(query, start, query.last_frame)]
    takes += [piece(read_take(h.take, args.asf, args.frame_rate, args.unit), h.first, h.last) for h in hits]
    names = ["query"] + [f"{i}. {h.take} from {h.first}" for i, h in enumerate(hits, 1)]
    write_page(takes, args.view, names=names, title=f"search: {args.query}")


INDEX = Verb(
    "index",
    "build a database of takes' features for search by example (all cores; only new or changed takes again)",
    _index_arguments,
    _index,
    description=(
        "Read every AMC and BVH take under the inputs, on all cores, and write what search compares: for each "
        "take, 17 points of the body seen from the hips in leg lengths and 25 relational features (a foot in "
        "front of the other, a hand above the head, ...) at 10 Hz, found through the rig tables, so that any "
        "rig, unit and up axis compare alike. A database already at -o is brought up to date: takes whose size "
        "and modification time are unchanged keep their features, gone ones are dropped."
    ),
    epilog="Example: motiontheater index captures/ -o captures.npz",
)

SEARCH = Verb(
    "search",
    "find the takes of a database that hold a motion like the query's (dynamic time warping)",
    _search_arguments,
    _search,
    description=(
        "List the -k takes of the database whose windows are nearest the query (the whole take, or --frames A:B "
        "of it) by dynamic time warping of the body features, one window per take, nearest first: the distance "
        "(per query row, 0 for the query itself), the frames as the file numbers them, and the take. The index "
        "of relational features chooses the windows to warp where it finds windows in -k takes or more, every "
        "window is warped otherwise; the windows warped are ranked exactly. With --frame N, frame search (motion "
        "matching): the -k frames whose feet, hips' velocity and path over the next second are nearest the "
        "query's at frame N (features are kept at 10 Hz: a hit is one of every tenth of a second)."
    ),
    epilog=(
        "Example: motiontheater index captures/ -o db.npz && motiontheater search db.npz 01_01.amc "
        "--frames 100:340 -k 3 --view hits.html\n"
        "Example: motiontheater index captures/ -o db.npz && motiontheater search db.npz 02_01.amc --json\n"
        "Example: motiontheater index captures/ -o db.npz && motiontheater search db.npz 02_01.amc --frame 200 -k 5"
    ),
)
