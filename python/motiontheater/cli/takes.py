"""How a verb reads its takes and names its output: the options every such verb shares.

A verb that reads takes adds :func:`add_take_options` and reads each take with :func:`take_of`,
so ``--asf``, ``--frame-rate``, ``--unit`` (and ``--frames`` where it offers a range) mean the
same everywhere.
"""

from __future__ import annotations

import argparse
import os

from ..formats.table import read_take, read_take_frames
from ..model.motion import Motion
from ..model.rig import choose_body
from ..model.units import UNIT_HELP


def add_take_options(parser: argparse.ArgumentParser, *, frames: bool = False, unit: bool = True) -> None:
    """How a take is read (``--asf``, ``--frame-rate``, ``--unit``, ``--body``) and, with ``frames``, the
    ``--frames A:B`` of a verb that works on a range of the take's frames; without ``unit``, no
    ``--unit`` (a verb whose result no length unit changes: search measures in leg lengths)."""
    parser.add_argument("--asf", help="the AMC's skeleton (default: the ASF beside it, by the CMU/HDM05 naming)")
    parser.add_argument("--frame-rate", type=float, metavar="HZ", help="frames per second when the AMC does not say")
    if unit:
        parser.add_argument(
            "--unit",
            metavar="UNIT",
            help=f"the takes' length unit: {UNIT_HELP} "
            "(default: a BVH's is told from its size, an ASF's is its :units length)",
        )
    else:
        parser.set_defaults(unit=None)
    parser.add_argument(
        "--body",
        metavar="JOINT",
        help="the joint that carries the body (default: the first whose position channels move, else the "
        "hips by name; see info)",
    )
    if frames:
        parser.add_argument("--frames", type=frame_range, metavar="A:B", help="only frames A to B of the take")


def take_of(args: argparse.Namespace, path: str, *, whole_frames: bool = False) -> Motion:
    """The take at ``path``, read as the options of :func:`add_take_options` say; with
    ``whole_frames``, the frames a file that breaks off holds whole (a recipe's whole_frames)."""
    if whole_frames:
        motion = read_take_frames(path, args.asf, args.frame_rate, args.unit)[0]
    else:
        motion = read_take(path, args.asf, args.frame_rate, args.unit)
    return motion if args.body is None else choose_body(motion, args.body)


def frame_range(text: str) -> tuple[int, int]:
    """``A:B`` as the frame numbers (A, B)."""
    try:
        first, last = (int(part) for part in text.split(":"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected FIRST:LAST frame numbers such as 100:250, got {text!r}") from None
    return first, last


def add_output_options(parser: argparse.ArgumentParser, what: str) -> None:
    """The output file, as the second argument or with ``-o``, and ``--in-place``."""
    parser.add_argument("output_file", nargs="?", metavar="OUT", help=f"{what} (or give it with -o)")
    parser.add_argument("-o", "--output", help=f"{what}")
    parser.add_argument(
        "--in-place",
        action="store_true",
        help="allow the output to replace the input, and an AMC's to replace the skeleton file beside it",
    )


def add_nan_option(parser: argparse.ArgumentParser) -> None:
    """``--allow-nan`` of a verb that writes takes: without it a result holding NaN or inf is
    refused, naming where (:func:`motiontheater.formats.table.write_take`)."""
    parser.add_argument(
        "--allow-nan",
        action="store_true",
        help="write values that are not numbers (NaN, inf) as they are; most readers refuse such a file",
    )


def settle_input(args: argparse.Namespace) -> str:
    """The take's path.  The older form ``verb SKELETON.asf TAKE.amc`` is read as ``verb
    TAKE.amc --asf SKELETON.asf`` (``args`` is set so)."""
    if args.input.lower().endswith(".asf") and args.output_file and args.output_file.lower().endswith(".amc"):
        args.input, args.asf, args.output_file = args.output_file, args.input, None
    return args.input


def output(args: argparse.Namespace, source: str) -> str:
    """The output file given once (second argument or ``-o``), refused when it is the input
    unless ``--in-place``."""
    chosen = [o for o in (args.output_file, args.output) if o]
    if len(chosen) != 1:
        raise ValueError("give the output file once: as the second argument or with -o OUT")
    target = chosen[0]
    if not args.in_place and os.path.exists(target) and os.path.samefile(source, target):
        raise ValueError(f"{target} is the input: write the result to another file, or pass --in-place")
    return target
