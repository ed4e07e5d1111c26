"""The verbs made from registered steps: one per step, ``steps`` that lists them, ``filter``
(one smoothing step by a flag) and ``apply`` (a recipe of steps).  Their filter flags and
recipe help serve ``batch`` too."""

from __future__ import annotations

import argparse
import itertools
import os
import sys
from functools import partial
from typing import Any

from ..editing.filtering import FILTERS
from ..editing.pipeline import Pipeline, toml_value
from ..formats.table import format_of, take_suffix, write_take_with_skeleton
from ..model.motion import Motion
from ..model.registry import Option, Step, lookup, steps
from .info import unit_notes
from .takes import add_nan_option, add_output_options, add_take_options, output, settle_input, take_of
from .verb import Verb, plain, prose

RECIPE_HELP = """\
A recipe is a TOML file of [[step]] tables, applied in order; each names a step
with run = "..." and gives its options (motiontheater steps lists them as a
recipe writes them); frames = [A, B] confines a step to frames A..B. For
example, steps.toml:

  [[step]]
  run = "median"
  size = 5

  [[step]]
  run = "slerp"
  frames = [100, 150]
  joints = ["lfemur", "rfemur"]
"""


def step_verbs() -> list[Verb]:
    """The verb of each registered step: ``motiontheater NAME TAKE -o OUT --option ...``."""
    return [_step_verb(step) for step in steps().values()]


# The value an example gives an option that has no default, by the option's name, else by its kind
EXAMPLES: dict[str, Any] = {
    "size": 5, "gains": (1, 1, 1.5, 1, 0.5), "rate": 60.0, "to": "02.asf", "map": "map.toml", "to_unit": "m", "contacts": "plants.csv",
}  # fmt: skip
KIND_EXAMPLES: dict[str, Any] = {
    "int": 3, "float": 1.0, "str": "text", "bool": True, "ints": (1, 2), "floats": (1.0, 2.0),
    "names": ("lfemur", "rfemur"), "path": "FILE", "frames": (100, 150),
}  # fmt: skip


def example(option: Option) -> Any:
    """A value of an option for examples: its first choice, its entry in EXAMPLES, or one of its kind."""
    if option.choices:
        return option.choices[0]
    return EXAMPLES.get(option.name, KIND_EXAMPLES[option.kind])


def _command_line(option: Option, value: Any) -> str:
    """A value as the command line writes it: lists comma-separated, frame ranges A:B."""
    if option.kind == "frames":
        return f"{value[0]}:{value[1]}"
    return ",".join(map(str, value)) if isinstance(value, tuple) else str(value)


def _step_verb(step: Step) -> Verb:
    required = "".join(f" {o.flag} {_command_line(o, example(o))}" for o in step.all_options if o.required)
    output = "out" + (step.suffixes[0] if step.is_exporter else ".amc")
    return Verb(
        step.name,
        plain(step.summary),
        partial(_step_arguments, step),
        _run_step,
        description=prose(
            f"{step.summary[:1].upper()}{step.summary[1:]}.",
            *step.description.split("\n\n"),
            flags={o.name: o.flag for o in step.all_options},
        ),
        epilog=f"Example: motiontheater {step.name} 01_01.amc{required} -o {output}",
        aliases=step.aliases,
        laid_out=True,
    )


def _step_arguments(step: Step, parser: argparse.ArgumentParser) -> None:
    what = "the file to write (" + (", ".join(step.suffixes) if step.is_exporter else ".amc or .bvh") + ")"
    if step.several:
        parser.add_argument("inputs", metavar="TAKE", nargs="+", help="the takes (AMC, BVH, ...), one skeleton")
        parser.add_argument("-o", "--output", required=True, help=what)
    else:
        parser.add_argument("input", metavar="TAKE", help="the AMC or BVH take")
        add_output_options(parser, what)
        add_nan_option(parser)
    add_take_options(parser)
    if step.dry_run is not None:
        parser.add_argument("--dry-run", action="store_true", help="print what the step would do; write nothing")
    for option in step.all_options:
        shown = option.required or option.default is None  # the help says what None means
        help_text = plain(option.help) + ("" if shown else f" (default: {_shown(option.default)})")
        if option.kind == "bool":
            parser.add_argument(option.flag, dest=option.name, action=argparse.BooleanOptionalAction, help=help_text)
        elif option.kind == "choice":
            parser.add_argument(
                option.flag, dest=option.name, type=option.parse, choices=option.choices, help=help_text
            )
        else:
            parser.add_argument(
                option.flag,
                dest=option.name,
                type=option.parse,
                metavar=option.metavar,
                required=option.required,
                help=help_text,
            )
    parser.set_defaults(step=step.name)


def _shown(value: Any) -> str:
    if isinstance(value, bool):
        return "on" if value else "off"
    return str(value)


def _run_step(args: argparse.Namespace) -> int:
    step = lookup(args.step)
    options = {o.name: getattr(args, o.name) for o in step.all_options if getattr(args, o.name) is not None}
    if step.several:
        return _export_takes(step, args, options)
    source = settle_input(args)
    if getattr(args, "dry_run", False):
        print(step.describe(take_of(args, source), **options))
        return 0
    target = output(args, source)
    if not step.is_exporter:
        options.update(_direction(step, options, target))
    motion = take_of(args, source)
    if step.is_exporter:
        step(motion, target, **options)
        print(f"{step.name}: wrote {motion.frames} frames of {source} to {target}")
        for note in unit_notes(motion, motion, target):
            print(note, file=sys.stderr)
        return 0
    result = step(motion, **options)
    written = _write_result(motion, result, target, args)
    print(f"{step.name}: {motion.frames} frames of {source} -> {result.frames} frames in {written}")
    return 0


def _export_takes(step: Step, args: argparse.Namespace, options: dict[str, Any]) -> int:
    """An exporter of several takes: every take given, into the one file -o names."""
    target = args.output
    for source in args.inputs:
        if os.path.exists(target) and os.path.samefile(source, target):
            raise ValueError(f"{target} is one of the takes read: write the file elsewhere")
    motions = [take_of(args, source) for source in args.inputs]
    step(motions if len(motions) > 1 else motions[0], target, **options)
    frames = sum(m.frames for m in motions)
    takes = f"{len(motions)} takes" if len(motions) > 1 else args.inputs[0]
    if options.get("rate") is not None:  # what was read, not what was written
        print(f"{step.name}: {frames} frames of {takes}, resampled to {options['rate']:g} Hz: wrote {target}")
    else:
        print(f"{step.name}: wrote {frames} frames of {takes} to {target}")
    for motion in motions:
        for note in unit_notes(motion, motion, target):
            print(note, file=sys.stderr)
    return 0


def _direction(step: Step, options: dict[str, Any], target: str) -> dict[str, Any]:
    """A ``to`` option naming a convention (convert's), when not given, is the output's: an .amc
    output means ASF/AMC, a .bvh one BVH.  (ValueError for an output no format holds takes in.)"""
    convention = format_of(target).convention
    if "to" in options or not any(o.name == "to" and convention in o.choices for o in step.options):
        return {}
    return {"to": convention}


def _write_result(motion: Motion, result: Motion, target: str, args: argparse.Namespace) -> str:
    """Write a step's result as its suffix says, an AMC with the ASF it is read with when that is
    not beside it already.  Returns what was written, in words."""
    skeleton = write_take_with_skeleton(result, target, allow_non_finite=args.allow_nan, replace=args.in_place)
    for note in unit_notes(motion, result, target):
        print(note, file=sys.stderr)
    return target if skeleton is None else f"{target} and its skeleton {skeleton}"


def _list_steps(args: argparse.Namespace) -> int:
    for name, step in steps().items():
        kind = f"exporter ({', '.join(step.suffixes)})" if step.is_exporter else "step"
        print(f"{name}: {plain(step.summary)} [{kind}]")
        for option in step.all_options:
            print(f"    {_recipe_line(option)}")
    return 0


def _recipe_line(option: Option) -> str:
    """An option as a recipe's [[step]] table writes it, its default's value or an example's, then
    what it is: ``size = 5  # required: window length ...``."""
    if option.required:
        value, which = example(option), "required"
    elif option.default is None:
        value, which = example(option), "unset by default; e.g."
    else:
        value, which = option.default, "default"
    choices = f" (one of {', '.join(map(toml_value, option.choices))})" if option.choices else ""
    return f"{option.name} = {toml_value(value)}  # {which}: {plain(option.help)}{choices}"


LISTING = Verb(
    "steps",
    "list every step and exporter with its options, as a recipe writes them",
    lambda parser: None,
    _list_steps,
    description=(
        "List every step and exporter: its name (a verb of its own, and run = NAME in a recipe), what "
        "it does, and each option as a recipe's [[step]] table writes it (TOML), with its default, or "
        "an example where it has none. On the command line an option is --NAME VALUE, with lists "
        "comma-separated (--joints lfemur,rfemur) and frame ranges as FIRST:LAST (--frames 100:150)."
    ),
    epilog="Example: motiontheater steps",
)


def add_filter_options(parser: argparse.ArgumentParser) -> None:
    """The filter flags shared by filter and batch."""
    for kind in FILTERS:
        parser.add_argument(f"--{kind}", type=int, metavar="N", help=f"{lookup(kind).summary} over N frames")
    names = Option("joints", "names", None, "")
    parser.add_argument(
        "--joints", type=names.parse, metavar="A,B,...", help="comma-separated joints to smooth (default: all)"
    )
    parser.add_argument("--no-translation", action="store_true", help="leave the root's translation alone")
    parser.add_argument(
        "--mode",
        default="nearest",
        choices=("nearest", "reflect", "mirror", "constant", "wrap"),
        help="how the edges are extended (default: nearest, the edge value held)",
    )


def filter_pipeline(args: argparse.Namespace) -> Pipeline:
    """The one filter the flags of :func:`add_filter_options` name, as a pipeline."""
    chosen = [(kind, getattr(args, kind)) for kind in FILTERS if getattr(args, kind) is not None]
    if len(chosen) != 1:
        raise ValueError("give exactly one of --median N, --mean N, --binomial N")
    kind, size = chosen[0]
    return Pipeline.of(kind, size=size, joints=args.joints, translation=not args.no_translation, mode=args.mode)


def _filter_arguments(parser: argparse.ArgumentParser) -> None:
    add_filter_options(parser)
    parser.add_argument("input", metavar="TAKE", help="the AMC or BVH take")
    add_output_options(parser, "the file to write (the input's format)")
    add_nan_option(parser)
    add_take_options(parser)


def _filter(args: argparse.Namespace) -> int:
    pipeline = filter_pipeline(args)
    source = settle_input(args)
    target = output(args, source)
    take_suffix(target)
    motion = take_of(args, source)
    written = _write_result(motion, pipeline.apply(motion), target, args)
    entry = pipeline.entries[0]
    which = ", ".join(args.joints) if args.joints else "all joints"
    print(f"{entry.name} {dict(entry.options)['size']} over {motion.frames} frames of {which}: wrote {written}")
    return 0


FILTER = Verb(
    "filter",
    "smooth a motion with a median, mean or binomial filter and write it",
    _filter_arguments,
    _filter,
    description=(
        "Smooth every channel (or the channels of the --joints given) over frames. Rotation "
        "channels are unwrapped first, so crossings of ±180 degrees stay small steps. Edges "
        "hold their value unless --mode says otherwise. Nothing is written when anything fails."
    ),
    epilog="Example: motiontheater filter --median 5 --joints lhumerus,rhumerus 01_01.amc -o smooth.amc",
)


def _apply_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("input", metavar="TAKE", help="the AMC or BVH take")
    add_output_options(parser, "the file to write")
    add_nan_option(parser)
    parser.add_argument("--recipe", required=True, metavar="FILE", help="the TOML recipe of steps")
    add_take_options(parser)


def _apply(args: argparse.Namespace) -> int:
    pipeline = Pipeline.read(args.recipe)
    source = settle_input(args)
    target = output(args, source)
    if pipeline.exporter is None:
        take_suffix(target)
    motion = take_of(args, source, whole_frames=pipeline.whole_frames)
    result = pipeline.apply(motion)
    if pipeline.exporter is not None:
        pipeline.write(result, target)
        written = target
    else:
        written = _write_result(motion, result, target, args)
    # a check's recipe may hold hundreds of steps: each run of one step told once, with its count
    runs = [(name, len(list(run))) for name, run in itertools.groupby(entry.name for entry in pipeline.entries)]
    names = ", ".join(name if count == 1 else f"{name} x{count}" for name, count in runs) or "no steps"
    if pipeline.whole_frames:
        names = f"the file's whole frames read, {names}"
    print(f"{args.recipe} ({names}) on {motion.frames} frames of {source}: wrote {written}")
    return 0


APPLY = Verb(
    "apply",
    "apply a recipe of steps (a TOML file) to a take",
    _apply_arguments,
    _apply,
    description=prose("Apply the steps of a recipe, in order, to a take and write the result.") + RECIPE_HELP,
    epilog="Example: motiontheater apply 01_01.amc --recipe steps.toml -o cleaned.amc",
    laid_out=True,
)
