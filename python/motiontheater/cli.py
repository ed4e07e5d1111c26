"""The ``motiontheater`` command line."""

from __future__ import annotations

import argparse
import os
import sys
import time
from collections.abc import Sequence

import numpy as np

import mtcore

from . import __version__
from .amc import read_amc, skeleton_path_for, write_amc
from .asf import read_asf, write_asf
from .examples import noisy_rotations
from .export import FORMATS, write_positions
from .filtering import FILTERS


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


def _positions(args: argparse.Namespace) -> int:
    motion = read_amc(args.motion, read_asf(args.skeleton), frame_rate=args.frame_rate)
    written = write_positions(motion, args.output, meters=args.meters, format=args.format)
    unit = "metres" if args.meters else "file units"
    print(
        f"wrote {motion.frames} frames x {len(motion.skeleton.joint_names)} joints ({unit}, {written}) to {args.output}"
    )
    return 0


def _chosen_filter(args: argparse.Namespace) -> tuple[str, int]:
    chosen = [(kind, getattr(args, kind)) for kind in FILTERS if getattr(args, kind) is not None]
    if len(chosen) != 1:
        raise ValueError("give exactly one of --median N, --mean N, --binomial N")
    return chosen[0]


def _filter_options(parser: argparse.ArgumentParser) -> None:
    """The filter flags shared by filter and batch."""
    for kind, what in (
        ("median", "moving median"),
        ("mean", "moving average"),
        ("binomial", "Pascal-weighted average (1 2 1 / 4 for 3)"),
    ):
        parser.add_argument(f"--{kind}", type=int, metavar="N", help=f"{what} over N frames (odd)")
    parser.add_argument("--asf", help="the skeleton (default: the ASF beside each take, by the CMU/HDM05 naming)")
    parser.add_argument("--joints", help="comma-separated joints to smooth (default: all)")
    parser.add_argument("--no-translation", action="store_true", help="leave the root's translation alone")
    parser.add_argument("--mode", default="nearest", help="edge mode: nearest, reflect, mirror, wrap, constant")
    parser.add_argument("--frame-rate", type=float, help="frames per second when the AMC does not say")


def _batch(args: argparse.Namespace) -> int:
    from . import batch

    kind, size = _chosen_filter(args)
    recipe = batch.Recipe(
        kind, size, tuple(args.joints.split(",")) if args.joints else None, not args.no_translation, args.mode
    )
    recipe.smoother(read_asf(args.asf)) if args.asf else None  # bad joints fail before any work
    jobs, settled = batch.plan_jobs(
        args.inputs,
        args.output,
        recipe,
        skeleton=args.asf,
        frame_rate=args.frame_rate,
        resume=args.resume,
        stream_above=int(args.stream_above * 1e6),
    )
    progress = batch.Progress(
        len(jobs), sum(os.path.getsize(j.input) for j in jobs), enabled=False if args.quiet or args.json else None
    )
    summary = batch.run(
        jobs,
        settled,
        workers=args.jobs,
        scheduler=args.scheduler,
        dask_local=args.dask,
        progress=progress,
        out=args.output,
    )
    if args.json:
        print(batch.report_json(summary))
    elif not args.quiet or summary.failed:
        print(summary.text(), file=sys.stderr if summary.failed else sys.stdout)
    return 1 if summary.failed else 0


def _read_any(path: str, asf: str | None, frame_rate: float | None):
    from .bvh import read_bvh

    if path.lower().endswith(".bvh"):
        return read_bvh(path)
    return read_amc(path, read_asf(asf or skeleton_path_for(path)), frame_rate=frame_rate)


def _convert(args: argparse.Namespace) -> int:
    from .bvh import write_bvh
    from .convert import to_asf, to_bvh

    motion = _read_any(args.input, args.asf, args.frame_rate)
    out = args.output
    if out.lower().endswith(".bvh"):
        write_bvh(to_bvh(motion, args.order), out)
        print(f"wrote {motion.frames} frames to {out}")
    elif out.lower().endswith(".amc"):
        converted = to_asf(motion)
        skeleton_out = os.path.splitext(out)[0] + ".asf"
        write_asf(converted.skeleton, skeleton_out)
        write_amc(converted, out)
        print(f"wrote {motion.frames} frames to {out} and its skeleton to {skeleton_out}")
    else:
        raise ValueError(f"the output must end in .bvh or .amc, got {out}")
    return 0


def _filter(args: argparse.Namespace) -> int:
    from .bvh import write_bvh

    kind, size = _chosen_filter(args)
    motion = _read_any(args.input, args.asf, args.frame_rate)
    joints = args.joints.split(",") if args.joints else None
    smoothed = motion.filter(kind, size, joints, translation=not args.no_translation, mode=args.mode)
    (write_bvh if motion.skeleton.convention == "bvh" else write_amc)(smoothed, args.output)
    which = ", ".join(joints) if joints else "all joints"
    print(f"{kind} {size} over {motion.frames} frames of {which}: wrote {args.output}")
    return 0


def _bench(args: argparse.Namespace) -> int:
    from . import bench

    scene, source = None, "synthetic random-walk angles"
    if args.amc:
        take = read_amc(args.amc, read_asf(args.asf or skeleton_path_for(args.amc)))
        scene = bench.scene_from_take(take)
        source = f"first {scene.shape[0]} frames of {args.amc}, rotation channels"
    report = bench.measure(
        scene, source, hour_frames=bench.HOUR[0] // (20 if args.quick else 1), repeat=2 if args.quick else 5
    )
    print(bench.as_json(report) if args.json else bench.markdown(report))
    return 0


def _combine(args: argparse.Namespace) -> int:
    from .scene import read_recipe

    scene = read_recipe(args.recipe)
    if args.dry_run:
        for track, plan in scene.plans():
            print(f"{track.name}:")
            print("  " + plan.describe().replace("\n", "\n  "))
        return 0
    if not args.output:
        raise ValueError("give -o OUT.amc (or --dry-run)")
    result = scene.render()
    write_amc(result, args.output)
    print(
        f"{len(scene.tracks)} track(s) over {scene.base.frames} frames: wrote {result.frames} frames "
        f"({result.first_frame}..{result.first_frame + result.frames - 1}) to {args.output}"
    )
    return 0


# --- seeing motions: view, plot, render, markers (issue 16) -------------------------------------


def _takes(args: argparse.Namespace, paths: Sequence[str]) -> list:
    return [_read_any(path, args.asf, args.frame_rate) for path in paths]


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

    from .view import write_page

    paths = [args.take, *args.more]
    takes = _takes(args, paths)
    out = Path(args.output or Path(args.take).stem + ".html")
    write_page(takes, out, names=[Path(p).name for p in paths], max_frames=args.max_frames)
    print(f"wrote {out} ({out.stat().st_size / 1e6:.2f} MB, {len(takes)} take(s), {takes[0].frames} frames)")
    if not args.no_open and not webbrowser.open(out.resolve().as_uri()):
        print(f"no browser could be started: open {out} in one", file=sys.stderr)
    return 0


def _plot(args: argparse.Namespace) -> int:
    from pathlib import Path

    from .plot import plot

    paths = [args.take, *args.compare]
    plot(
        _takes(args, paths),
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

    from .render import render

    paths = [args.take, *args.compare]

    def progress(done: int, total: int) -> None:
        print(f"\rrendering frame {done} of {total}", end="" if done < total else "\n", file=sys.stderr)

    written = render(
        _takes(args, paths),
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


def _markers(args: argparse.Namespace) -> int:
    motion = _read_any(args.take, args.asf, args.frame_rate)
    if args.output.lower().endswith(".c3d"):
        from .markers import write_c3d

        write_c3d(motion, args.output)
        written, unit = "c3d", "millimetres"
    else:
        written = write_positions(motion, args.output, meters=args.meters)
        unit = "metres" if args.meters else "file units"
    points = len(motion.skeleton.point_names)
    print(f"wrote {motion.frames} frames x {points} markers ({unit}, {written}) to {args.output}")
    return 0


def _add_seeing_verbs(verbs) -> None:
    """The parsers of view, plot, render and markers."""

    def take_options(parser: argparse.ArgumentParser) -> None:
        parser.add_argument(
            "--asf", help="the skeleton of AMC takes (default: the ASF beside each, by CMU/HDM05 naming)"
        )
        parser.add_argument("--frame-rate", type=float, help="frames per second when an AMC does not say")

    view = verbs.add_parser(
        "view",
        help="write an offline HTML page that plays, compares and edits takes, and open it",
        description=(
            "Write ONE self-contained HTML file (no network needed, ever) and open it in the browser: a 3D "
            "skeleton player (drag to orbit, wheel to zoom, right-drag to pan; Space plays, arrows step, R "
            "reverses, D doubles the speed, L loops, F follows the root), the joint tree with the selected "
            "joint's channels and an axis-angle glyph of its rotation, its curves (click to seek, drag to "
            "select frames), more takes overlaid for comparison, and an editor that stacks interpolators and "
            "filters over frame ranges, previews them and exports the stack as a recipe for motiontheater. "
            "Example: motiontheater view 01_01.amc smooth.amc -o compare.html"
        ),
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
    take_options(view)
    view.set_defaults(run=_view)

    plot = verbs.add_parser(
        "plot",
        help="draw channel curves of a take, and of takes to compare, to PNG, SVG or PDF",
        description=(
            "Draw one panel per channel of the --joints, over frames: the take in black and each --compare "
            "take in a colour over it (e.g. before and after a filter, as the thesis's figures 4.26-4.39). "
            "Needs matplotlib: pip install 'motiontheater[plot]'. Example: motiontheater plot 01_01.amc "
            "--joints lfemur,ltibia --compare smooth.amc --frames 100:400 -o fig.png"
        ),
    )
    plot.add_argument("take", help="the take (AMC or BVH)")
    plot.add_argument("--joints", required=True, help="comma-separated joints whose channels to draw")
    plot.add_argument("--dofs", help="only these dofs, comma-separated (e.g. rx,rz)")
    plot.add_argument("--compare", action="append", default=[], metavar="OTHER", help="a take to overlay (repeatable)")
    plot.add_argument("--frames", type=_frame_range, metavar="A:B", help="only frames A to B of the take")
    plot.add_argument("--title", help="the figure's title (default: the takes' names)")
    plot.add_argument("--dpi", type=float, default=150.0, help="dots per inch of a PNG (default 150)")
    plot.add_argument("-o", "--output", required=True, help="the figure: .png, .svg or .pdf")
    take_options(plot)
    plot.set_defaults(run=_plot)

    animation = verbs.add_parser(
        "render",
        help="render the skeleton as an animated GIF or MP4",
        description=(
            "Render the take's skeleton in motion, in real time at --fps, from the viewer's camera following "
            "the root (--fixed-camera: one camera over the whole take); --compare takes are ghosted over it. "
            "GIF needs matplotlib and pillow (pip install 'motiontheater[plot]'); MP4 also ffmpeg on the PATH. "
            "Example: motiontheater render 01_01.amc --frames 1:600 -o walk.gif"
        ),
    )
    animation.add_argument("take", help="the take (AMC or BVH)")
    animation.add_argument("-o", "--output", required=True, help="the animation: .gif or .mp4")
    animation.add_argument("--compare", action="append", default=[], metavar="OTHER", help="a take to ghost over it")
    animation.add_argument("--fps", type=float, default=25.0, help="frames per second of the animation (default 25)")
    animation.add_argument("--size", type=_size, default=(480, 360), metavar="WxH", help="pixels (default 480x360)")
    animation.add_argument("--frames", type=_frame_range, metavar="A:B", help="only frames A to B of the take")
    animation.add_argument("--fixed-camera", action="store_true", help="do not follow the root")
    take_options(animation)
    animation.set_defaults(run=_render)

    markers = verbs.add_parser(
        "markers",
        help="export joints and end sites as virtual markers: C3D, TRC, CSV or NPZ",
        description=(
            "Write every joint and end site of an AMC or BVH take as a marker per frame, by the output's "
            "suffix: .c3d (millimetres, rate, labels, missing samples marked; needs pip install "
            "'motiontheater[c3d]'), .trc (OpenSim; use --meters for CMU and HDM05), .csv or .npz. "
            "Example: motiontheater markers 01_01.amc -o 01_01.c3d"
        ),
    )
    markers.add_argument("take", help="the take (AMC or BVH)")
    markers.add_argument("-o", "--output", required=True, help="output file: .c3d, .trc, .csv or .npz")
    markers.add_argument("--meters", action="store_true", help="TRC, CSV, NPZ in metres (default: file units)")
    take_options(markers)
    markers.set_defaults(run=_markers)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="motiontheater",
        description=(
            "Clean, cut, splice and smooth motion-capture data. "
            "Run 'motiontheater demo' to smooth a built-in noisy 120 Hz capture."
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

    positions = verbs.add_parser(
        "positions",
        help="export the world position of every joint per frame (CSV, NPZ or TRC)",
        description=(
            "Compute every joint's world position per frame by forward kinematics (the root, then "
            "each bone's end point) and write them as CSV (frame, time, joint.x/.y/.z columns), "
            "NumPy .npz or TRC (OpenSim markers). Example: motiontheater positions 01.asf 01_01.amc "
            "-o 01_01.trc --meters"
        ),
    )
    positions.add_argument("skeleton", help="the ASF file")
    positions.add_argument("motion", help="the AMC file")
    positions.add_argument("-o", "--output", required=True, help="output file: .csv, .npz or .trc")
    positions.add_argument("--format", choices=FORMATS, help="output format (default: from the suffix)")
    positions.add_argument("--meters", action="store_true", help="lengths in metres (default: file units)")
    positions.add_argument("--frame-rate", type=float, help="frames per second when the AMC does not say")
    positions.set_defaults(run=_positions)

    smooth = verbs.add_parser(
        "filter",
        help="smooth a motion with a median, mean or binomial filter and write it",
        description=(
            "Smooth every channel (or the channels of the --joints given) over frames. Rotation "
            "channels are unwrapped first, so crossings of ±180 degrees stay small steps. Edges "
            "hold their value unless --mode says otherwise. Nothing is written when anything fails. "
            "Example: motiontheater filter --median 5 --joints lhumerus,rhumerus 01_01.amc "
            "--asf 01.asf -o smooth.amc"
        ),
    )
    _filter_options(smooth)
    smooth.add_argument("input", help="the AMC or BVH file")
    smooth.add_argument("-o", "--output", required=True, help="the file to write (the input's format)")
    smooth.set_defaults(run=_filter)

    many = verbs.add_parser(
        "batch",
        help="filter whole capture databases: folders, globs, all cores or a Dask cluster",
        description=(
            "Apply a filter to every AMC under the inputs (files, folders searched recursively, "
            "globs), writing into an output folder that mirrors the input tree, with each take's "
            "skeleton found by the CMU/HDM05 naming (or --asf). Runs on all cores (--jobs), or on a "
            "Dask cluster (--dask for a local one, --scheduler tcp://HOST:PORT). Each output is "
            "written under a temporary name and renamed when complete; --resume skips outputs newer "
            "than their inputs; a bad take is reported and the others go on; the exit status is 1 "
            "when any take failed. Takes above --stream-above MB are streamed in chunks. Example: "
            "motiontheater batch --median 5 --jobs 2 captures/ -o smoothed/"
        ),
    )
    _filter_options(many)
    many.add_argument("inputs", nargs="+", help="AMC and BVH files, folders or globs")
    many.add_argument("-o", "--output", required=True, help="the output folder")
    many.add_argument("--jobs", type=int, default=0, help="processes (default: every core)")
    many.add_argument("--resume", action="store_true", help="skip takes whose output is newer than the input")
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

    conversion = verbs.add_parser(
        "convert",
        help="convert between ASF/AMC and BVH (forward kinematics gives the same points)",
        description=(
            "Convert a motion between ASF/AMC and BVH, by the output's suffix. AMC to BVH: a joint at "
            "each bone's start carries the bone's rotation. BVH to AMC: a bone per segment, named "
            "after the joint it ends at; the skeleton is written beside it as OUT.asf. Examples: "
            "motiontheater convert 01_01.amc 01_01.bvh --asf 01.asf; motiontheater convert walk.bvh walk.amc"
        ),
    )
    conversion.add_argument("input", help="an AMC (with its ASF) or a BVH file")
    conversion.add_argument("output", help="OUT.bvh or OUT.amc")
    conversion.add_argument("--asf", help="the input AMC's skeleton (default: the ASF beside it)")
    conversion.add_argument("--order", default="ZXY", help="rotation channel order of the BVH written (default ZXY)")
    conversion.add_argument("--frame-rate", type=float, help="frames per second when the AMC does not say")
    conversion.set_defaults(run=_convert)

    recipe = verbs.add_parser(
        "combine",
        help="lay motion tracks over a base motion, as a TOML recipe says, and write an AMC",
        description=(
            "Combine motions as the MotionTheater thesis's MotionCombiner does: each track of the "
            "recipe is cut, time-scaled, blended or root-preserved and applied to chosen joints over "
            "the scene so far. --dry-run prints every track's frame map and borders instead. See "
            "motiontheater.scene.read_recipe for the recipe's keys."
        ),
    )
    recipe.add_argument("recipe", help="the TOML recipe")
    recipe.add_argument("-o", "--output", help="the AMC file to write")
    recipe.add_argument("--dry-run", action="store_true", help="print the frame maps and borders, write nothing")
    recipe.set_defaults(run=_combine)

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


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.verb is None:
        parser.print_help()
        return 0
    try:
        return args.run(args)
    except (ValueError, TypeError, OSError, RuntimeError) as exc:
        print(f"motiontheater {args.verb}: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
