"""A viewer page: one self-contained HTML file that plays, compares and edits motions offline.

:func:`write_page` writes a page that needs no network and no other file:
its script, style and data are inside it.  It shows a skeleton player (a
perspective view drawn with Canvas 2D, a floor grid, orbit/zoom/pan and a
camera that follows the body), the joint tree with the selected joint's
channel values and an axis-angle glyph of its rotation, the selected joint's
channel curves with a playhead, several takes compared (overlaid curves and
ghosted skeletons, aligned in time), footplants when given (``contacts=``), and an editor that
stacks the registered interpolators (:mod:`motiontheater.editing.interpolators`) and
filters (:mod:`motiontheater.editing.filtering`) over frame ranges, previews them
(JavaScript ports of those steps, equal to about 1e-12) and exports the
stack as a recipe for ``motiontheater apply``.

What the page holds, and why: each take's channel values and its joint tree,
not positions.  The channels are what the joint table, the curves and the
editing preview need, and the page computes forward kinematics from them
(the port of mtcore's kernel, to about 1e-12), so positions would only add
three numbers per point per frame.  Values are stored exactly: a value equal
to m / 10^d (integers |m| < 2^26, d <= 22: every value read from a decimal
of up to seven significant digits and 22 decimals) is a 32-bit word, which
the page divides back to the same double; any other value is kept as its
float64.  Words go in four byte planes, deflated, base64 (the page inflates
them with the browser's DecompressionStream).  CMU 01_01 (2,751 frames x 62
channels) makes a page of 0.65 MB.

Takes longer than ``max_frames`` frames are decimated (1 frame in k is kept,
k the smallest that fits) and the page says so; editing is then off,
since filters and interpolators work on every frame.

Each take is drawn standing along +y: its up axis (given, or found from its
frames by :func:`~motiontheater.feet.upright.take_up`) is turned up, and the
floor grid, the footplant rings and the camera's orbit are in that turned
frame.  The camera follows the take's body
(:func:`~motiontheater.model.rig.body_view`: the joint that travels), and the
joints that stand still above it (a game rig's static root) are not drawn,
nor their bones.  Everything else the page shows and edits is the take's own:
its joints, channels and values (the recipe names them as the take does), and
forward kinematics in its own axes; only the drawing is turned.
"""

from __future__ import annotations

import base64
import json
import math
import warnings
import zlib
from collections.abc import Mapping, Sequence
from importlib.resources import files

import numpy as np

from ..._io import Source, output
from ..._version import __version__
from ...editing.filtering import FILTERS
from ...editing.interpolators import INTERPOLATORS
from ...feet.contacts import Contacts
from ...feet.legs import resolve_legs
from ...feet.upright import take_up
from ...model.motion import Motion
from ...model.registry import Joints, lookup
from ...model.rig import body_view

__all__ = ["DEFAULT_MAX_FRAMES", "EDIT_STEPS", "page", "write_page"]

DEFAULT_MAX_FRAMES = 30_000
"""Frames per take a page holds before it decimates (250 s at 120 Hz; a one-hour take keeps every 15th)."""

EDIT_STEPS: tuple[dict, ...] = tuple(
    {
        "kind": kind,
        "label": lookup(kind).summary,
        "run": kind,  # the registered step's name, as recipes give it
        "options": {},  # fixed options written with it
        "size": kind in FILTERS,  # takes a window size
    }
    for kind in (*INTERPOLATORS, "median3", *FILTERS)
)
"""The editor's steps (registered steps whose preview the page computes) and how each is written in
a recipe: a ``[[step]]`` table with ``run``, the fixed ``options``, ``size`` where it takes one,
``frames = [first, last]`` (frame numbers) and ``joints`` (absent: all)."""

_APPLY_HINT = "motiontheater apply TAKE --recipe RECIPE.toml -o OUT"
_EXACT_LIMIT = 2**26  # |m| below this fits the word's 27 bits beside the 5 of d
_POW10 = 10.0 ** np.arange(23)  # exact doubles: 10^22 is the largest power of ten that is one


def _encode_values(values: np.ndarray) -> dict[str, str]:
    """Values (frames, channels) as the page stores them (see the module docstring)."""
    flat = np.ascontiguousarray(values.T).ravel()
    words = np.full(flat.shape, 31, np.int32)
    pending, rest = np.arange(flat.size), flat  # the values without a word yet, and where they go
    with np.errstate(over="ignore", invalid="ignore"):
        for d, scale in enumerate(_POW10):
            m = np.rint(rest * scale)
            exact = (np.abs(m) < _EXACT_LIMIT) & (m / scale == rest)
            words[pending[exact]] = (m[exact].astype(np.int32) << 5) | d
            pending, rest = pending[~exact], rest[~exact]
            if not len(pending):
                break
    planes = words.astype("<i4").view(np.uint8).reshape(-1, 4).T.tobytes()
    return {
        "data": base64.b64encode(zlib.compress(planes, 6)).decode("ascii"),
        "exceptions": base64.b64encode(rest.astype("<f8").tobytes()).decode("ascii"),
    }


def _spans(flags: np.ndarray) -> list[list[int]]:
    """[first, last] index pairs of the runs of True."""
    padded = np.concatenate([[False], flags, [False]]).astype(np.int8)
    edges = np.flatnonzero(np.diff(padded))
    return [[int(a), int(b) - 1] for a, b in zip(edges[::2], edges[1::2])]


Footplants = Mapping[str, np.ndarray] | Contacts
"""A take's footplants: a contacts table, or flags per frame of named points."""


def _plant_rows(motion: Motion, label: str, step: int, contacts: Footplants | None, legs: Joints) -> list[dict]:
    """The footplant rows of a take as the page draws them: label, point index, spans of shown frames."""
    if contacts is None:
        return []
    if isinstance(contacts, Contacts):
        contacts.check_take(motion.first_frame, motion.frames)
        marks = contacts.marks(resolve_legs(motion.skeleton, legs))
    else:
        points = motion.skeleton.point_names
        marks = []
        for point, flags in contacts.items():
            if point not in points:
                raise ValueError(f"footplants name '{point}', which is not a point of {label}")
            marks.append((point, points.index(point), np.asarray(flags, bool)))
    rows = []
    for name, where, flags in marks:
        if flags.shape != (motion.frames,):
            raise ValueError(
                f"footplants of '{name}' must have one flag per frame ({motion.frames}), got {flags.shape}"
            )
        rows.append({"label": name, "point": where, "spans": _spans(flags[::step])})
    return rows


def _take_data(
    motion: Motion, label: str, step: int, contacts: Footplants | None, legs: Joints, up: str | None
) -> dict:
    skeleton = motion.skeleton
    tree = skeleton.tree
    names = skeleton.joint_names
    index = {name: i for i, name in enumerate(names)}
    values = motion.values[::step]
    shown_plants = _plant_rows(motion, label, step, contacts, legs)
    upright = take_up(motion, up)
    seen = body_view(motion)
    return {
        "name": label,
        "frameRate": motion.frame_rate,
        "firstFrame": motion.first_frame,
        "step": step,
        "totalFrames": motion.frames,
        "frames": len(values),
        "convention": skeleton.convention,
        "angleUnit": skeleton.angle_unit,
        "metersPerUnit": skeleton.meters_per_unit,
        "up": upright.axis,
        "turn": upright.turn.ravel().tolist(),
        "body": index[seen.body],
        "still": [index[j] for j in seen.still_above],
        "joints": list(names),
        "points": list(skeleton.point_names),
        "children": [[index[c] for c in skeleton.children(n)] for n in names],
        "dofs": [list(skeleton.dofs(n)) for n in names],
        "firstColumn": [skeleton.first_column(n) for n in names],
        "channels": [list(c) for c in motion.channels],
        "parent": tree.parent.tolist(),
        "order": tree.order.tolist(),
        "axis": tree.axis.ravel().tolist(),
        "direction": tree.direction.ravel().tolist(),
        "segment": tree.segment.ravel().tolist(),
        "dofStart": tree.dof_start.tolist(),
        "dofKind": tree.dof_kind.tolist(),
        "dofColumn": tree.dof_column.tolist(),
        "parentFrame": np.asarray(tree.parent_frame, dtype=np.uint8).tolist(),
        "angleScale": tree.angle_scale,
        "plants": shown_plants,
        "values": _encode_values(values),
    }


def page(
    takes: Sequence[Motion],
    *,
    names: Sequence[str] | None = None,
    contacts: Sequence[Footplants | None] | None = None,
    legs: Joints = None,
    max_frames: int = DEFAULT_MAX_FRAMES,
    title: str | None = None,
    up: str | None = None,
    plants: Sequence[Footplants | None] | None = None,
) -> str:
    """The HTML text of a viewer page for one or more takes.

    The first take is the one played and edited; the others are compared
    with it (ghosted skeletons and dashed curves at the same time from each
    take's start).  ``names`` label the takes (default "take 1", ...).
    ``contacts`` gives, per take, optional footplants, marked on the feet (a
    ring on the floor and a dot on the point, while planted) and on the
    timeline under the curves (a row each): a :class:`~motiontheater.feet.contacts.Contacts`
    table of that take (its heels and balls; its feet are those of the legs
    found by name, or of ``legs``: hip,knee,ankle[,toe] of the left then the
    right leg), or a mapping point name (one of ``skeleton.point_names``) ->
    bool array with one flag per frame, True where the point is planted.  A
    take of more than ``max_frames`` frames is shown decimated to at most that
    many, and editing is then off.  ``up`` is the axis that points up in every
    take ("y", "z", "-y", ...; ValueError otherwise), drawn up; by default each
    take's own, found from its frames (:func:`~motiontheater.feet.upright.take_up`:
    y for ASF/AMC).  The camera follows each take's body and no joint standing
    still above it is drawn (see the module docstring).  ``plants`` is the old
    name of ``contacts`` (deprecated).
    """
    contacts = _renamed(contacts, plants)
    if not takes:
        raise ValueError("give at least one take to view")
    if isinstance(max_frames, bool) or not isinstance(max_frames, int) or max_frames < 2:
        raise ValueError(f"max_frames must be an integer of at least 2, got {max_frames!r}")
    labels = list(names) if names is not None else [f"take {i + 1}" for i in range(len(takes))]
    plant_list = list(contacts) if contacts is not None else [None] * len(takes)
    if len(labels) != len(takes) or len(plant_list) != len(takes):
        raise ValueError(f"give one name and one footplant mapping per take ({len(takes)})")
    for motion, label in zip(takes, labels):
        if motion.frames == 0:
            raise ValueError(f"{label} has no frames to show")
    steps = [max(1, math.ceil(m.frames / max_frames)) for m in takes]
    notes = [
        f"{label}: 1 frame in {k} of its {m.frames:,} is shown ({m.frame_rate / k:g} Hz)"
        for m, label, k in zip(takes, labels, steps)
        if k > 1
    ]
    data = {
        "version": 1,
        "steps": list(EDIT_STEPS),
        "applyHint": _APPLY_HINT,
        "editable": steps[0] == 1,
        "note": (
            "; ".join(notes) + f" (pages hold up to {max_frames:,} frames per take; editing is off)" if notes else ""
        ),
        "takes": [_take_data(m, label, k, p, legs, up) for m, label, k, p in zip(takes, labels, steps, plant_list)],
    }
    text = title or "motiontheater: " + " vs ".join(labels)
    resources = files(__package__)
    html = resources.joinpath("page.html").read_text(encoding="utf-8")
    # "<" escaped: nothing in the data can close the script element that holds it
    payload = json.dumps(data, separators=(",", ":"), allow_nan=False).replace("<", "\\u003c")
    for key, value in (
        ("__GENERATOR__", f"motiontheater {__version__}"),
        ("__TITLE__", _escape(text)),
        ("__CSS__", resources.joinpath("view.css").read_text(encoding="utf-8")),
        ("__JS__", resources.joinpath("view.js").read_text(encoding="utf-8")),
        ("__DATA__", payload),
    ):
        html = html.replace(key, value)
    return html


def _escape(text: str) -> str:
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;").replace('"', "&quot;")


def _renamed(
    contacts: Sequence[Footplants | None] | None, plants: Sequence[Footplants | None] | None
) -> Sequence[Footplants | None] | None:
    """``contacts``, or ``plants`` (its old name) with a DeprecationWarning at the caller of page or write_page."""
    if plants is None:
        return contacts
    warnings.warn("plants= is deprecated: give the footplants as contacts=", DeprecationWarning, stacklevel=3)
    if contacts is not None:
        raise ValueError("give the footplants once, as contacts= (plants= is its old name)")
    return plants


def write_page(takes: Sequence[Motion], target: Source, **options) -> None:
    """Write :func:`page` (same options) to a path (atomically) or a binary file object."""
    if "plants" in options:
        options["contacts"] = _renamed(options.pop("contacts", None), options.pop("plants"))
    text = page(takes, **options)
    with output(target) as f:
        f.write(text.encode("utf-8"))
