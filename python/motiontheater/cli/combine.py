"""The ``combine`` verb: motion tracks laid over a base motion, as a TOML scene says."""

from __future__ import annotations

import argparse

from ..editing.scene import RECIPE_HELP as SCENE_HELP
from ..editing.scene import read_recipe
from ..formats.table import write_take_with_skeleton
from .takes import add_nan_option
from .verb import Verb, prose


def _arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("recipe", help="the TOML recipe")
    parser.add_argument("-o", "--output", help="the take to write (.amc or .bvh, as the motions)")
    parser.add_argument("--dry-run", action="store_true", help="print the frame maps and borders, write nothing")
    add_nan_option(parser)
    parser.add_argument(
        "--in-place", action="store_true", help="allow the output's skeleton file to replace another one there"
    )


def _combine(args: argparse.Namespace) -> int:
    scene = read_recipe(args.recipe)
    if args.dry_run:
        for track, plan in scene.plans():
            print(f"{track.name}:")
            print("  " + plan.describe().replace("\n", "\n  "))
        return 0
    if not args.output:
        raise ValueError("give -o OUT.amc (or --dry-run)")
    result = scene.render()
    write_take_with_skeleton(result, args.output, allow_non_finite=args.allow_nan, replace=args.in_place)
    print(
        f"{len(scene.tracks)} track(s) over {scene.base.frames} frames: wrote {result.frames} frames "
        f"({result.first_frame}..{result.last_frame}) to {args.output}"
    )
    return 0


COMBINE = Verb(
    "combine",
    "lay motion tracks over a base motion, as a TOML recipe says, and write the result",
    _arguments,
    _combine,
    description=prose(
        "Combine motions as the MotionTheater thesis's MotionCombiner does: each track of the "
        "recipe is cut, time-scaled, blended or root-preserved and applied to chosen joints over "
        "the scene so far. --dry-run prints every track's frame map and borders instead."
    )
    + SCENE_HELP,
    epilog="Example: motiontheater combine scene.toml --dry-run; motiontheater combine scene.toml -o out.amc",
    laid_out=True,
)
