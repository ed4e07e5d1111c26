"""The ``bench`` verb: the thesis's timing table measured again (the work is in :mod:`.bench`,
imported when the verb runs)."""

from __future__ import annotations

import argparse

from ..formats.table import read_take
from .verb import Verb


def _arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--json", action="store_true", help="print JSON for tracking")
    parser.add_argument("--amc", help="use the first 267 frames of this take as the scene")
    # the scene is the take's rotation angles: its frame rate and length unit change no timing
    parser.add_argument("--asf", help="the take's skeleton (default: the ASF beside it)")
    parser.add_argument("--quick", action="store_true", help="a 3-minute capture instead of an hour, fewer rounds")


def _bench(args: argparse.Namespace) -> int:
    from .bench import HOUR, as_json, markdown, measure, scene_from_take

    scene, source = None, "synthetic random-walk angles"
    if args.amc:
        take = read_take(args.amc, args.asf)
        scene = scene_from_take(take)
        source = f"first {scene.shape[0]} frames of {args.amc}, rotation channels"
    report = measure(scene, source, hour_frames=HOUR[0] // (20 if args.quick else 1), repeat=2 if args.quick else 5)
    print(as_json(report) if args.json else markdown(report))
    return 0


BENCH = Verb(
    "bench",
    "time the filters against the thesis's 2004 table and today's peers",
    _arguments,
    _bench,
    description=(
        "Reproduce the MotionTheater thesis's timing table (24,030 values: 30 joints x 267 "
        "frames x 3 rotations) beside mtcore, a plain Python loop, scipy.ndimage and bottleneck, "
        "and time a one-hour 120 Hz capture against numpy's copy. Prints Markdown, or JSON."
    ),
    epilog="Example: motiontheater bench --quick",
)
