"""The ``motiontheater`` command line.

Every registered step (see :mod:`motiontheater.model.registry`) is a verb of its
own, built here from its options; the other verbs (demo, steps, filter,
apply, batch, combine, bench) are written out below.
"""

from __future__ import annotations

import argparse
import logging
import os
import shutil
import sys
import textwrap
import time
from collections.abc import Sequence
from typing import Any

import numpy as np

import mtcore

from .._signals import terminate_as_interrupt
from .._version import __version__
from ..editing.filtering import FILTERS
from ..editing.pipeline import Pipeline
from ..editing.scene import RECIPE_HELP as SCENE_HELP
from ..editing.scene import read_recipe
from ..formats.table import companion_path, read_take, skeleton_for, take_suffix, write_skeleton, write_take
from ..model.motion import Motion
from ..model.registry import Option, Step, lookup, steps
from ..model.units import UNIT_HELP
from .examples import noisy_rotations
from .info import as_text, describe, unit_notes

RECIPE_HELP = """\
A recipe is a TOML file of [[step]] tables, applied in order; each names a step
with run = "..." and gives its options (motiontheater steps lists them);
frames = [A, B] confines a step to frames A..B:

  [[step]]
  run = "median"
  size = 5

  [[step]]
  run = "slerp"
  frames = [100, 150]
  joints = ["lfemur", "rfemur"]
"""


def _demo(args: argparse.Namespace) -> int:
    clean, noisy = noisy_rotations(seconds=args.seconds, seed=args.seed)
    frames, channels = noisy.shape
    print(
        f"Synthetic capture: {frames} frames at 120 Hz x {channels} rotation channels (degrees),\n"
        f"Gaussian jitter of 1.5 deg and single-frame spikes of 20-40 deg on 0.5% of samples.\n"
        f"Filters of size {args.size} along the frames, edge mode 'nearest'.\n"
    )
    rows = [("unfiltered", noisy, 0.0)]
    for name, fn in FILTERS.items():
        start = time.perf_counter()
        out = fn(noisy, args.size, axis=0, mode="nearest")
        rows.append((name, out, time.perf_counter() - start))
    start = time.perf_counter()
    chained = mtcore.binomial_filter1d(
        mtcore.median_filter1d(noisy, args.size, axis=0, mode="nearest"), args.size, axis=0, mode="nearest"
    )
    rows.append(("median, then binomial", chained, time.perf_counter() - start))

    print("| filter | RMS error (deg) | max error (deg) | samples off by > 5 deg | time |")
    print("|---|---:|---:|---:|---:|")
    for name, values, seconds in rows:
        err = np.abs(values - clean)
        rms = float(np.sqrt(np.mean(err**2)))
        timing = f"{seconds * 1e6:.0f} us" if seconds else "-"
        print(f"| {name} | {rms:.3f} | {float(err.max()):.2f} | {int((err > 5).sum())} | {timing} |")
    return 0


def _take_options(parser: argparse.ArgumentParser) -> None:
    """How a take is read: the flags every verb that reads takes shares."""
    parser.add_argument("--asf", help="the AMC's skeleton (default: the ASF beside it, by the CMU/HDM05 naming)")
    parser.add_argument("--frame-rate", type=float, metavar="HZ", help="frames per second when the AMC does not say")
    parser.add_argument(
        "--unit",
        metavar="UNIT",
        help=f"the takes' length unit: {UNIT_HELP} "
        "(default: a BVH's is told from its size, an ASF's is its :units length)",
    )


def _output_options(parser: argparse.ArgumentParser, what: str) -> None:
    parser.add_argument("output_file", nargs="?", metavar="OUT", help=f"{what} (or give it with -o)")
    parser.add_argument("-o", "--output", help=f"{what}")
    parser.add_argument("--in-place", action="store_true", help="allow the output to replace the input")


def _inputs(args: argparse.Namespace) -> tuple[str, str | None]:
    """(take, skeleton): the older form ``verb SKELETON.asf TAKE.amc`` is read too."""
    take, asf = args.input, args.asf
    if take.lower().endswith(".asf") and args.output_file and args.output_file.lower().endswith(".amc"):
        take, asf, args.output_file = args.output_file, take, None
    return take, asf


def _output(args: argparse.Namespace, source: str) -> str:
    chosen = [o for o in (args.output_file, args.output) if o]
    if len(chosen) != 1:
        raise ValueError("give the output file once: as the second argument or with -o OUT")
    _refuse_overwriting(source, chosen[0], args.in_place)
    return chosen[0]


def _refuse_overwriting(source: str, target: str, in_place: bool) -> None:
    if not in_place and os.path.exists(target) and os.path.samefile(source, target):
        raise ValueError(f"{target} is the input: write the result to another file, or pass --in-place")


def _write(motion: Motion, result: Motion, source: str, target: str) -> str:
    """Write a step's result as its suffix says; an AMC of a new skeleton gets its ASF beside it.
    Returns what was written, in words."""
    write_take(result, target)
    for note in unit_notes(motion, result, target):
        print(note, file=sys.stderr)
    skeleton = companion_path(result, target)
    if skeleton is not None and result.skeleton is not motion.skeleton:
        write_skeleton(result.skeleton, skeleton)
        return f"{target} and its skeleton {skeleton}"
    return target


def _run_step(args: argparse.Namespace) -> int:
    step = lookup(args.step)
    options = {o.name: getattr(args, o.name) for o in step.all_options if getattr(args, o.name) is not None}
    source, asf = _inputs(args)
    if getattr(args, "dry_run", False):
        print(step.describe(read_take(source, asf, args.frame_rate), **options))
        return 0
    target = _output(args, source)
    if not step.is_exporter:
        take_suffix(target)
    motion = read_take(source, asf, args.frame_rate, args.unit)
    if step.is_exporter:
        step(motion, target, **options)
        print(f"{step.name}: wrote {motion.frames} frames of {source} to {target}")
        for note in unit_notes(motion, motion, target):
            print(note, file=sys.stderr)
        return 0
    result = step(motion, **options)
    written = _write(motion, result, source, target)
    print(f"{step.name}: {motion.frames} frames of {source} -> {result.frames} frames in {written}")
    return 0


def _apply(args: argparse.Namespace) -> int:
    pipeline = Pipeline.read(args.recipe)
    source, asf = _inputs(args)
    target = _output(args, source)
    if pipeline.exporter is None:
        take_suffix(target)
    motion = read_take(source, asf, args.frame_rate, args.unit)
    result = pipeline.apply(motion)
    if pipeline.exporter is not None:
        pipeline.write(result, target)
        written = target
    else:
        written = _write(motion, result, source, target)
    names = ", ".join(entry.name for entry in pipeline.entries) or "no steps"
    print(f"{args.recipe} ({names}) on {motion.frames} frames of {source}: wrote {written}")
    return 0


def _filter(args: argparse.Namespace) -> int:
    pipeline = _filter_pipeline(args)
    source, asf = _inputs(args)
    target = _output(args, source)
    take_suffix(target)
    motion = read_take(source, asf, args.frame_rate, args.unit)
    written = _write(motion, pipeline.apply(motion), source, target)
    entry = pipeline.entries[0]
    which = ", ".join(args.joints) if args.joints else "all joints"
    print(f"{entry.name} {dict(entry.options)['size']} over {motion.frames} frames of {which}: wrote {written}")
    return 0


def _filter_pipeline(args: argparse.Namespace) -> Pipeline:
    chosen = [(kind, getattr(args, kind)) for kind in FILTERS if getattr(args, kind) is not None]
    if len(chosen) != 1:
        raise ValueError("give exactly one of --median N, --mean N, --binomial N")
    kind, size = chosen[0]
    return Pipeline.of(kind, size=size, joints=args.joints, translation=not args.no_translation, mode=args.mode)


def _filter_options(parser: argparse.ArgumentParser) -> None:
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


def _info(args: argparse.Namespace) -> int:
    import json

    motion = read_take(args.input, args.asf, args.frame_rate, args.unit)
    skeleton_file = skeleton_for(args.input, args.asf)
    facts = describe(motion, args.input, skeleton_file, frame_rate_given=args.frame_rate is not None)
    print(json.dumps(facts, indent=2) if args.json else as_text(facts))
    return 0


def _steps(args: argparse.Namespace) -> int:
    for name, step in steps().items():
        kind = f"exporter ({', '.join(step.suffixes)})" if step.is_exporter else "step"
        print(f"{name}: {step.summary} [{kind}]")
        for option in step.all_options:
            default = "required" if option.required else f"default {option.default!r}"
            choices = f" ({', '.join(map(str, option.choices))})" if option.choices else ""
            print(f"    {option.name}: {option.help}{choices}; {default}")
    return 0


def _batch(args: argparse.Namespace) -> int:
    from ..databases.batch import Progress, plan_jobs, report_json, run

    has_filter = any(getattr(args, kind) is not None for kind in FILTERS)
    if bool(args.recipe) == has_filter:
        raise ValueError("give a recipe (--recipe FILE) or one filter (--median N, --mean N or --binomial N)")
    pipeline = Pipeline.read(args.recipe) if args.recipe else _filter_pipeline(args)
    jobs, settled = plan_jobs(
        args.inputs,
        args.output,
        pipeline,
        skeleton=args.asf,
        frame_rate=args.frame_rate,
        unit=args.unit,
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
    write_take(result, args.output)
    print(
        f"{len(scene.tracks)} track(s) over {scene.base.frames} frames: wrote {result.frames} frames "
        f"({result.first_frame}..{result.last_frame}) to {args.output}"
    )
    return 0


def _ground_options(parser: argparse.ArgumentParser) -> None:
    """The flags of the footskate verbs (skate, contacts, view's plants): they are the cleanup step's."""
    cleanup = {o.name: o for o in lookup("cleanup").options}
    for name in ("floor", "up", "legs"):
        option = cleanup[name]
        parser.add_argument(
            option.flag,
            dest=name,
            type=option.parse,
            metavar=option.metavar,
            choices=option.choices or None,
            help=option.help,
        )


def _skate(args: argparse.Namespace) -> int:
    from ..feet.skate import skate_metrics

    motion = read_take(args.input, args.asf, args.frame_rate, args.unit)
    report = skate_metrics(motion, args.contacts, legs=args.legs, up=args.up, floor=args.floor)
    print(report.to_json() if args.json else report.text())
    return 0


def _contacts(args: argparse.Namespace) -> int:
    from ..feet.footskate import contacts_of, prepare

    target = _output(args, args.input)
    motion = read_take(args.input, args.asf, args.frame_rate, args.unit)
    arrays, ground, mpu = prepare(motion, legs=args.legs, up=args.up, floor=args.floor)
    table = contacts_of(None, motion, arrays, ground, mpu)
    table.to_csv(target)
    print(f"contacts: {len(table)} plants in {motion.frames} frames of {args.input}: wrote {target}")
    return 0


def _step_verb(verbs: Any, step: Step) -> None:
    """The verb of a registered step: ``motiontheater NAME TAKE -o OUT --option ...``."""
    what = "the file to write (" + (", ".join(step.suffixes) if step.is_exporter else ".amc or .bvh") + ")"
    required = " ".join(f"{o.flag} {o.metavar or o.name.upper()}" for o in step.all_options if o.required)
    example = f"Example: motiontheater {step.name} 01_01.amc {required + ' ' if required else ''}-o out"
    example += step.suffixes[0] if step.is_exporter else ".amc"
    parser = verbs.add_parser(
        step.name,
        aliases=list(step.aliases),
        help=step.summary,
        description=_prose(f"{step.summary[:1].upper()}{step.summary[1:]}.", *step.description.split("\n\n")),
        epilog=example,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("input", metavar="TAKE", help="the AMC or BVH take")
    _output_options(parser, what)
    _take_options(parser)
    if step.dry_run is not None:
        parser.add_argument("--dry-run", action="store_true", help="print what the step would do; write nothing")
    for option in step.all_options:
        shown = option.required or option.default is None  # the help says what None means
        help_text = option.help + ("" if shown else f" (default: {_shown(option.default)})")
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
    parser.set_defaults(run=_run_step, step=step.name)


def _prose(*paragraphs: str) -> str:
    """Paragraphs filled to the terminal's width, for --help texts that also hold examples."""
    width = min(shutil.get_terminal_size().columns, 100) - 2
    return "".join(textwrap.fill(" ".join(p.split()), width) + "\n\n" for p in paragraphs if p.strip())


def _shown(value: Any) -> str:
    if isinstance(value, bool):
        return "on" if value else "off"
    return str(value)


# --- seeing motions: view, plot, render (issue 16) ----------------------------------------------


def _frame_range(text: str) -> tuple[int, int]:
    try:
        first, last = (int(part) for part in text.split(":"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected FIRST:LAST frame numbers such as 100:250, got {text!r}") from None
    return first, last


def _size(text: str) -> tuple[int, int]:
    try:
        width, height = (int(part) for part in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT in pixels such as 480x360, got {text!r}") from None
    return width, height


def _view(args: argparse.Namespace) -> int:
    import webbrowser
    from pathlib import Path

    from ..views.viewer import write_page

    paths = [args.take, *args.more]
    takes = [read_take(path, args.asf, args.frame_rate, args.unit) for path in paths]
    out = Path(args.output or Path(args.take).stem + ".html")
    plants: list[Any] = [None] * len(takes)
    if args.plants or args.contacts:
        from ..feet.footskate import contacts_of, prepare

        for i, motion in enumerate(takes):
            given = args.contacts if i == 0 else None  # a contacts table is of the first take
            if given is None and not args.plants:
                continue
            arrays, ground, mpu = prepare(motion, legs=args.legs, up=args.up, floor=args.floor)
            plants[i] = contacts_of(given, motion, arrays, ground, mpu)
    names = [Path(p).name for p in paths]
    write_page(takes, out, names=names, plants=plants, legs=args.legs, max_frames=args.max_frames)
    shown = "".join(f", {len(p)} footplants on {name}" for p, name in zip(plants, names) if p is not None)
    print(f"wrote {out} ({out.stat().st_size / 1e6:.2f} MB, {len(takes)} take(s), {takes[0].frames} frames{shown})")
    if not args.no_open and not webbrowser.open(out.resolve().as_uri()):
        print(f"no browser could be started: open {out} in one", file=sys.stderr)
    return 0


def _plot(args: argparse.Namespace) -> int:
    from pathlib import Path

    from ..views.plot import plot

    paths = [args.take, *args.compare]
    plot(
        [read_take(path, args.asf, args.frame_rate) for path in paths],
        args.output,
        joints=args.joints.split(","),
        dofs=args.dofs.split(",") if args.dofs else None,
        frames=args.frames,
        names=[Path(p).name for p in paths],
        title=args.title,
        dpi=args.dpi,
    )
    print(f"wrote {args.output}")
    return 0


def _render(args: argparse.Namespace) -> int:
    from pathlib import Path

    from ..views.render import render

    paths = [args.take, *args.compare]

    def progress(done: int, total: int) -> None:
        print(f"\rrendering frame {done} of {total}", end="" if done < total else "\n", file=sys.stderr)

    written = render(
        [read_take(path, args.asf, args.frame_rate) for path in paths],
        args.output,
        fps=args.fps,
        size=args.size,
        frames=args.frames,
        names=[Path(p).name for p in paths],
        follow=not args.fixed_camera,
        progress=progress if sys.stderr.isatty() else None,
    )
    print(f"wrote {written} frames at {args.fps:g} fps to {args.output}")
    return 0


def _add_seeing_verbs(verbs: Any) -> None:
    """The parsers of view, plot and render (the C3D markers are the registered exporter c3d)."""
    view = verbs.add_parser(
        "view",
        help="write an offline HTML page that plays, compares and edits takes, and open it",
        description=(
            "Write ONE self-contained HTML file (no network needed, ever) and open it in the browser: a 3D "
            "skeleton player (drag to orbit, wheel to zoom, right-drag to pan; Space plays, arrows step, R "
            "reverses, D doubles the speed, L loops, F follows the root), the joint tree with the selected "
            "joint's channels and an axis-angle glyph of its rotation, its curves (click to seek, drag to "
            "select frames), more takes overlaid for comparison, and an editor that stacks interpolators and "
            "filters over frame ranges, previews them and exports the stack as a recipe for motiontheater "
            "apply. Takes longer than --max-frames are shown decimated, with a note, and editing off. "
            "Footplants (--plants: detected; --contacts FILE: a table) are marked green on the feet, listed "
            "beside the clock and drawn as rows under the curves."
        ),
        epilog="Example: motiontheater view 01_01.amc smooth.amc -o compare.html; "
        "motiontheater view 07_05.amc cleaned.amc --plants",
    )
    view.add_argument("take", help="the take to play and edit (AMC or BVH)")
    view.add_argument("more", nargs="*", help="takes to compare with it, ghosted and overlaid")
    view.add_argument("-o", "--output", help="the page to write (default: TAKE's name with .html, here)")
    view.add_argument("--no-open", action="store_true", help="write the page but do not open a browser")
    view.add_argument(
        "--max-frames",
        type=int,
        default=30_000,
        help="longer takes are shown decimated to at most this many frames, editing off (default 30000)",
    )
    view.add_argument(
        "--plants",
        action="store_true",
        help="detect the footplants of every take (as motiontheater contacts does) and mark them on the feet "
        "and on the timeline",
    )
    view.add_argument(
        "--contacts",
        metavar="FILE",
        help="mark the first take's footplants from this CSV table (as motiontheater contacts writes it)",
    )
    _ground_options(view)
    _take_options(view)
    view.set_defaults(run=_view)

    plot = verbs.add_parser(
        "plot",
        help="draw channel curves of a take, and of takes to compare, to PNG, SVG or PDF",
        description=(
            "Draw one panel per channel of the --joints, over frames: the take in black and each --compare "
            "take in a colour over it (e.g. before and after a filter, as the thesis's figures 4.26-4.39). "
            "Needs matplotlib: pip install 'motiontheater[plot]'."
        ),
        epilog="Example: motiontheater plot 01_01.amc --joints lfemur,ltibia --compare smooth.amc --frames 100:400 "
        "-o fig.png",
    )
    plot.add_argument("take", help="the take (AMC or BVH)")
    plot.add_argument("--joints", required=True, help="comma-separated joints whose channels to draw")
    plot.add_argument("--dofs", help="only these dofs, comma-separated (e.g. rx,rz)")
    plot.add_argument("--compare", action="append", default=[], metavar="OTHER", help="a take to overlay (repeatable)")
    plot.add_argument("--frames", type=_frame_range, metavar="A:B", help="only frames A to B of the take")
    plot.add_argument("--title", help="the figure's title (default: the takes' names)")
    plot.add_argument("--dpi", type=float, default=150.0, help="dots per inch of a PNG (default 150)")
    plot.add_argument("-o", "--output", required=True, help="the figure: .png, .svg or .pdf")
    _take_options(plot)
    plot.set_defaults(run=_plot)

    animation = verbs.add_parser(
        "render",
        help="render the skeleton as an animated GIF or MP4",
        description=(
            "Render the take's skeleton in motion, in real time at --fps, from the viewer's camera following "
            "the root (--fixed-camera: one camera over the whole take); --compare takes are ghosted over it. "
            "GIF needs matplotlib and pillow (pip install 'motiontheater[plot]'); MP4 also ffmpeg on the PATH."
        ),
        epilog="Example: motiontheater render 01_01.amc --frames 1:600 -o walk.gif",
    )
    animation.add_argument("take", help="the take (AMC or BVH)")
    animation.add_argument("-o", "--output", required=True, help="the animation: .gif or .mp4")
    animation.add_argument("--compare", action="append", default=[], metavar="OTHER", help="a take to ghost over it")
    animation.add_argument("--fps", type=float, default=25.0, help="frames per second of the animation (default 25)")
    animation.add_argument("--size", type=_size, default=(480, 360), metavar="WxH", help="pixels (default 480x360)")
    animation.add_argument("--frames", type=_frame_range, metavar="A:B", help="only frames A to B of the take")
    animation.add_argument("--fixed-camera", action="store_true", help="do not follow the root")
    _take_options(animation)
    animation.set_defaults(run=_render)


def build_parser() -> argparse.ArgumentParser:
    """The parser of every verb: those written here and one per registered step."""
    parser = argparse.ArgumentParser(
        prog="motiontheater",
        description=(
            "Clean, cut, splice and smooth motion-capture data (ASF/AMC and BVH). "
            "Run 'motiontheater demo' to smooth a built-in noisy 120 Hz capture; "
            "'motiontheater steps' lists every step and its options."
        ),
    )
    parser.add_argument("--version", action="version", version=f"motiontheater {__version__}")
    verbs = parser.add_subparsers(dest="verb", metavar="<verb>")
    demo = verbs.add_parser(
        "demo",
        help="smooth a built-in noisy synthetic 120 Hz capture and compare the filters",
        description=(
            "Make a synthetic 120 Hz capture (90 rotation channels, the thesis's scene), add "
            "jitter and marker-pop spikes, smooth it with each filter and print how close each "
            "result comes to the clean motion."
        ),
    )
    demo.add_argument("--size", type=int, default=5, help="filter window in frames (default 5)")
    demo.add_argument("--seconds", type=float, default=10.0, help="length of the capture (default 10)")
    demo.add_argument("--seed", type=int, default=0, help="random seed of the synthetic data")
    demo.set_defaults(run=_demo)

    listing = verbs.add_parser("steps", help="list every step and exporter with its options")
    listing.set_defaults(run=_steps)

    about = verbs.add_parser(
        "info",
        help="describe a take: frames, rate, units, height, up axis, joint tree and channel ranges",
        description=(
            "Describe a take (AMC or BVH): its frames, frame rate, duration and first frame; its length "
            "unit, how that was chosen (stated by the ASF, detected from the character's size, given with "
            "--unit, or assumed) and how to set another; the character's height in metres and in file "
            "units and its up axis; and the joint tree with each channel's range over the take. --json "
            "prints the same as JSON for programs."
        ),
        epilog="Example: motiontheater info walk01.bvh ; motiontheater info 01_01.amc --json",
    )
    about.add_argument("input", metavar="TAKE", help="the AMC or BVH take")
    about.add_argument("--json", action="store_true", help="print JSON (NaN as null)")
    _take_options(about)
    about.set_defaults(run=_info)

    smooth = verbs.add_parser(
        "filter",
        help="smooth a motion with a median, mean or binomial filter and write it",
        description=(
            "Smooth every channel (or the channels of the --joints given) over frames. Rotation "
            "channels are unwrapped first, so crossings of ±180 degrees stay small steps. Edges "
            "hold their value unless --mode says otherwise. Nothing is written when anything fails."
        ),
        epilog="Example: motiontheater filter --median 5 --joints lhumerus,rhumerus 01_01.amc -o smooth.amc",
    )
    _filter_options(smooth)
    smooth.add_argument("input", metavar="TAKE", help="the AMC or BVH take")
    _output_options(smooth, "the file to write (the input's format)")
    _take_options(smooth)
    smooth.set_defaults(run=_filter)

    recipe_run = verbs.add_parser(
        "apply",
        help="apply a recipe of steps (a TOML file) to a take",
        description=_prose("Apply the steps of a recipe, in order, to a take and write the result.") + RECIPE_HELP,
        epilog="Example: motiontheater apply 01_01.amc --recipe steps.toml -o cleaned.amc",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    recipe_run.add_argument("input", metavar="TAKE", help="the AMC or BVH take")
    _output_options(recipe_run, "the file to write")
    recipe_run.add_argument("--recipe", required=True, metavar="FILE", help="the TOML recipe of steps")
    _take_options(recipe_run)
    recipe_run.set_defaults(run=_apply)

    for step in steps().values():
        _step_verb(verbs, step)

    many = verbs.add_parser(
        "batch",
        help="apply a filter or a recipe to whole capture databases: folders, globs, all cores or a Dask cluster",
        description=_prose(
            "Apply a filter (--median N, --mean N, --binomial N) or a recipe of steps (--recipe FILE) to "
            "every AMC and BVH take under the inputs (files, folders searched recursively, globs), writing "
            "into an output folder that mirrors the input tree, with each take's skeleton found by the "
            "CMU/HDM05 naming (or --asf). Runs on all cores (--jobs), or on a Dask cluster (--dask for a "
            "local one, --scheduler tcp://HOST:PORT). Each output is written under a temporary name and "
            "renamed when complete; --resume skips takes already done; a bad take is reported and the "
            "others go on; the exit status is 1 when any take failed. Takes above --stream-above MB are "
            "streamed in chunks when the recipe is a single filter."
        )
        + RECIPE_HELP,
        epilog="Example: motiontheater batch --median 5 --jobs 2 captures/ -o smoothed/",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    _filter_options(many)
    many.add_argument("--recipe", metavar="FILE", help="a TOML recipe of steps (instead of a filter flag)")
    many.add_argument("inputs", nargs="+", help="AMC and BVH files, folders or globs")
    many.add_argument("-o", "--output", required=True, help="the output folder")
    _take_options(many)
    many.add_argument("--jobs", type=int, default=0, help="processes (default: every core)")
    many.add_argument(
        "--resume",
        action="store_true",
        help="skip takes already done by this recipe from inputs unchanged since (the output folder's manifest says)",
    )
    many.add_argument("--in-place", action="store_true", help="allow outputs to replace their inputs")
    many.add_argument("--quiet", action="store_true", help="no progress bar or summary (failures still reported)")
    many.add_argument("--json", action="store_true", help="print a JSON summary")
    many.add_argument("--dask", action="store_true", help="run on a local Dask cluster of --jobs workers")
    many.add_argument("--scheduler", help="run on the Dask cluster at this address (tcp://HOST:PORT)")
    many.add_argument(
        "--stream-above",
        type=float,
        default=256.0,
        metavar="MB",
        help="stream takes larger than this many MB in chunks (default 256)",
    )
    many.set_defaults(run=_batch)

    recipe = verbs.add_parser(
        "combine",
        help="lay motion tracks over a base motion, as a TOML recipe says, and write the result",
        description=_prose(
            "Combine motions as the MotionTheater thesis's MotionCombiner does: each track of the "
            "recipe is cut, time-scaled, blended or root-preserved and applied to chosen joints over "
            "the scene so far. --dry-run prints every track's frame map and borders instead."
        )
        + SCENE_HELP,
        epilog="Example: motiontheater combine scene.toml --dry-run; motiontheater combine scene.toml -o out.amc",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    recipe.add_argument("recipe", help="the TOML recipe")
    recipe.add_argument("-o", "--output", help="the take to write (.amc or .bvh, as the motions)")
    recipe.add_argument("--dry-run", action="store_true", help="print the frame maps and borders, write nothing")
    recipe.set_defaults(run=_combine)

    skating = verbs.add_parser(
        "skate",
        help="measure footskate: sliding, skating ratio, penetration and float of each foot",
        description=(
            "Measure how much a take's planted feet slide (mm from where each plant began), how often "
            "they skate (the motion-generation papers' ratio: a foot within 5 cm of the floor moving faster "
            "than 0.5 m/s, which a walk's swing does too, and the same over the steps in which a point is "
            "planted: 0 on the plants detected on the take itself, which hold no point that fast), how deep "
            "they go below the floor and how high planted points float. The plants are detected unless "
            "--contacts gives a table; the floor is fitted unless --floor gives its level. Prints a Markdown "
            "table, or JSON. To measure what a cleanup did, give both takes the same table: detection on the "
            "cleaned take finds other plants."
        ),
        epilog=(
            "Example: motiontheater contacts 07_05-walk.amc -o plants.csv && motiontheater cleanup "
            "07_05-walk.amc --contacts plants.csv -o clean.amc && motiontheater skate clean.amc --asf "
            "07-walk.asf --contacts plants.csv"
        ),
    )
    skating.add_argument("input", metavar="TAKE", help="the AMC or BVH take")
    skating.add_argument("--contacts", metavar="FILE", help="the footplants CSV to measure on (default: detected)")
    skating.add_argument("--json", action="store_true", help="print JSON")
    _ground_options(skating)
    _take_options(skating)
    skating.set_defaults(run=_skate)

    plants = verbs.add_parser(
        "contacts",
        help="detect the footplants of a take and write them as a CSV table to read and edit",
        description=(
            "Detect when each foot's heel and ball stand on the floor (height above rest and speed, "
            "with hysteresis) and write the table: one row per plant, foot,point,first,last (frame "
            "numbers, both included). Edit it (delete a row, add one) and give it back to cleanup "
            "with --contacts."
        ),
        epilog="Example: motiontheater contacts 07_05-walk.amc -o plants.csv",
    )
    plants.add_argument("input", metavar="TAKE", help="the AMC or BVH take")
    _output_options(plants, "the CSV file to write")
    _ground_options(plants)
    _take_options(plants)
    plants.set_defaults(run=_contacts)

    timing = verbs.add_parser(
        "bench",
        help="time the filters against the thesis's 2004 table and today's peers",
        description=(
            "Reproduce the MotionTheater thesis's timing table (24,030 values: 30 joints x 267 "
            "frames x 3 rotations) beside mtcore, a plain Python loop, scipy.ndimage and bottleneck, "
            "and time a one-hour 120 Hz capture against numpy's copy. Prints Markdown, or JSON."
        ),
    )
    timing.add_argument("--json", action="store_true", help="print JSON for tracking")
    timing.add_argument("--amc", help="use the first 267 frames of this take as the scene")
    timing.add_argument("--asf", help="the take's skeleton (default: the ASF beside it)")
    timing.add_argument("--quick", action="store_true", help="a 3-minute capture instead of an hour, fewer rounds")
    timing.set_defaults(run=_bench)
    _add_seeing_verbs(verbs)
    return parser


def _notes() -> logging.Handler:
    """A handler that prints what steps note on the package's logger (a cut-off chosen, gaps left) to stderr."""
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("%(message)s"))
    handler.setLevel(logging.INFO)
    return handler


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status: 0 done, 1 some takes failed (batch), 2 a
    one-line reason on failure, 130 interrupted (Ctrl-C or SIGTERM: nothing partial is left)."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.verb is None:
        parser.print_help()
        return 0
    logger, notes = logging.getLogger("motiontheater"), _notes()
    logger.addHandler(notes)
    level = logger.level
    logger.setLevel(logging.INFO)
    try:
        with terminate_as_interrupt():
            status = int(args.run(args))
        sys.stdout.flush()  # here, where a closed pipe is caught, not at exit
        return status
    except KeyboardInterrupt:
        print(f"motiontheater {args.verb}: interrupted; nothing was left half-written", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # the reader of our output went away (| head): say nothing more, to no one
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except MemoryError:
        print(f"motiontheater {args.verb}: not enough memory for this take", file=sys.stderr)
        return 2
    except (ValueError, TypeError, OSError, RuntimeError) as exc:
        print(f"motiontheater {args.verb}: {exc}", file=sys.stderr)
        return 2
    finally:
        logger.removeHandler(notes)
        logger.setLevel(level)


if __name__ == "__main__":
    sys.exit(main())
