"""The verbs that show motions: ``view`` (the offline HTML page), ``plot`` (curve figures) and
``render`` (GIF or MP4).  Plot and render import matplotlib, slow to load, when they run."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from ..views.viewer import DEFAULT_MAX_FRAMES, write_page
from .feet import add_ground_options
from .takes import add_take_options, take_of
from .verb import Verb

DETECT = True
"""``--contacts`` given with no FILE: detect the footplants of every take."""


def _view_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("take", help="the take to play and edit (AMC or BVH)")
    parser.add_argument("more", nargs="*", help="takes to compare with it, ghosted and overlaid")
    parser.add_argument("-o", "--output", help="the page to write (default: TAKE's name with .html, here)")
    parser.add_argument("--no-open", action="store_true", help="write the page but do not open a browser")
    parser.add_argument(
        "--max-frames",
        type=int,
        default=DEFAULT_MAX_FRAMES,
        help="longer takes are shown decimated to at most this many frames, editing off "
        f"(default {DEFAULT_MAX_FRAMES})",
    )
    parser.add_argument(
        "--contacts",
        nargs="?",
        const=DETECT,
        metavar="FILE",
        help="mark footplants on the feet and on the timeline: with no FILE, those of every take, detected as "
        "motiontheater contacts does; with FILE, the first take's from this CSV table (as motiontheater "
        "contacts writes it). Give it after the takes, or its FILE is taken for one",
    )
    parser.add_argument("--plants", action="store_true", help="the old name of --contacts with no FILE")
    add_ground_options(parser)
    add_take_options(parser)


def _view(args: argparse.Namespace) -> int:
    import webbrowser

    if args.plants:
        print("motiontheater view: --plants is deprecated: give --contacts (with no FILE)", file=sys.stderr)
    detect = args.plants or args.contacts is DETECT
    table = None if args.contacts is DETECT else args.contacts
    paths = [args.take, *args.more]
    takes = [take_of(args, path) for path in paths]
    out = Path(args.output or Path(args.take).stem + ".html")
    contacts: list[Any] = [None] * len(takes)
    if detect or table:
        from ..feet.footskate import contacts_of, prepare

        for i, motion in enumerate(takes):
            given = table if i == 0 else None  # a contacts table is of the first take
            if given is None and not detect:
                continue
            arrays, ground, mpu = prepare(motion, legs=args.legs, up=args.up, floor=args.floor)
            contacts[i] = contacts_of(given, motion, arrays, ground, mpu)
    names = [Path(p).name for p in paths]
    write_page(takes, out, names=names, contacts=contacts, legs=args.legs, max_frames=args.max_frames, up=args.up)
    shown = "".join(f", {len(c)} footplants on {name}" for c, name in zip(contacts, names) if c is not None)
    print(f"wrote {out} ({out.stat().st_size / 1e6:.2f} MB, {len(takes)} take(s), {takes[0].frames} frames{shown})")
    if not args.no_open and not webbrowser.open(out.resolve().as_uri()):
        print(f"no browser could be started: open {out} in one", file=sys.stderr)
    return 0


def _plot_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("take", help="the take (AMC or BVH)")
    parser.add_argument("--joints", required=True, help="comma-separated joints whose channels to draw")
    parser.add_argument("--dofs", help="only these dofs, comma-separated (e.g. rx,rz)")
    parser.add_argument(
        "--compare", action="append", default=[], metavar="OTHER", help="a take to overlay (repeatable)"
    )
    parser.add_argument("--title", help="the figure's title (default: the takes' names)")
    parser.add_argument("--dpi", type=float, default=150.0, help="dots per inch of a PNG (default 150)")
    parser.add_argument("-o", "--output", required=True, help="the figure: .png, .svg or .pdf")
    add_take_options(parser, frames=True)


def _plot(args: argparse.Namespace) -> int:
    from ..views.plot import plot

    paths = [args.take, *args.compare]
    plot(
        [take_of(args, path) for path in paths],
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


def _size(text: str) -> tuple[int, int]:
    try:
        width, height = (int(part) for part in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT in pixels such as 480x360, got {text!r}") from None
    return width, height


def _render_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("take", help="the take (AMC or BVH)")
    parser.add_argument("-o", "--output", required=True, help="the animation: .gif or .mp4")
    parser.add_argument("--compare", action="append", default=[], metavar="OTHER", help="a take to ghost over it")
    parser.add_argument("--fps", type=float, default=25.0, help="frames per second of the animation (default 25)")
    parser.add_argument("--size", type=_size, default=(480, 360), metavar="WxH", help="pixels (default 480x360)")
    parser.add_argument("--fixed-camera", action="store_true", help="do not follow the body")
    add_ground_options(parser, ("up",))
    add_take_options(parser, frames=True)


def _render(args: argparse.Namespace) -> int:
    from ..views.render import render

    paths = [args.take, *args.compare]

    def progress(done: int, total: int) -> None:
        print(f"\rrendering frame {done} of {total}", end="" if done < total else "\n", file=sys.stderr)

    written = render(
        [take_of(args, path) for path in paths],
        args.output,
        fps=args.fps,
        size=args.size,
        frames=args.frames,
        names=[Path(p).name for p in paths],
        follow=not args.fixed_camera,
        up=args.up,
        progress=progress if sys.stderr.isatty() else None,
    )
    print(f"wrote {written} frames at {args.fps:g} fps to {args.output}")
    return 0


VERBS = [
    Verb(
        "view",
        "write an offline HTML page that plays, compares and edits takes, and open it",
        _view_arguments,
        _view,
        description=(
            "Write ONE self-contained HTML file (no network needed, ever) and open it in the browser: a 3D "
            "skeleton player (drag to orbit, wheel to zoom, right-drag to pan; Space plays, arrows step, R "
            "reverses, D doubles the speed, L loops, F follows the body), the joint tree with the selected "
            "joint's channels and an axis-angle glyph of its rotation, its curves (click to seek, drag to "
            "select frames), more takes overlaid for comparison, and an editor that stacks interpolators and "
            "filters over frame ranges, previews them and exports the stack as a recipe for motiontheater "
            "apply. Takes longer than --max-frames are shown decimated, with a note, and editing off. "
            "Footplants (--contacts: detected; --contacts FILE: a table) are marked green on the feet, listed "
            "beside the clock and drawn as rows under the curves. Each take is drawn standing on its up axis "
            "(found from its frames, where the hips are above the ankles; --up gives it for every take), the camera "
            "follows the joint that travels, and a static joint above it (a game rig's root) is not drawn."
        ),
        epilog="Example: motiontheater view 01_01.amc --contacts\n"
        "Example: motiontheater median 01_01.amc --size 5 -o smooth.amc && "
        "motiontheater view 01_01.amc smooth.amc --asf 01.asf -o compare.html",
    ),
    Verb(
        "plot",
        "draw channel curves of a take, and of takes to compare, to PNG, SVG or PDF",
        _plot_arguments,
        _plot,
        description=(
            "Draw one panel per channel of the --joints, over frames: the take in black and each --compare "
            "take in a colour over it (e.g. before and after a filter, as the thesis's figures 4.26-4.39). "
            "Needs matplotlib: pip install 'motiontheater[plot]'."
        ),
        epilog="Example: motiontheater plot 01_01.amc --joints lfemur,ltibia --frames 100:400 -o fig.png\n"
        "Example: motiontheater median 01_01.amc --size 5 -o smooth.amc && "
        "motiontheater plot 01_01.amc --joints lfemur,ltibia --compare smooth.amc --asf 01.asf --frames 100:400 -o fig.png",
    ),
    Verb(
        "render",
        "render the skeleton as an animated GIF or MP4",
        _render_arguments,
        _render,
        description=(
            "Render the take's skeleton in motion, in real time at --fps, from the viewer's camera following "
            "the root (--fixed-camera: one camera over the whole take); --compare takes are ghosted over it. "
            "GIF needs matplotlib and pillow (pip install 'motiontheater[plot]'); MP4 also ffmpeg on the PATH."
        ),
        epilog="Example: motiontheater render 01_01.amc --frames 1:600 -o 01_01.gif",
    ),
]
