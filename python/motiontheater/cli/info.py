"""What a take holds, for people and programs: ``motiontheater info TAKE``.

:func:`describe` gathers it as plain data (JSON-ready: NaN as None) and
:func:`as_text` puts it in words: the frames, rate, duration and first
frame; the length unit, how it was chosen and how to choose another; the
character's height in metres and file units and its up axis; and the joint
tree with each channel's range over the take.  :func:`unit_notes` is what the
verbs that write takes say about units; ``INFO`` is the verb.
"""

from __future__ import annotations

import argparse
import math
import os
import textwrap
from typing import Any

import numpy as np

from ..feet.upright import take_forward, take_up
from ..formats.bvh import NAMES as BVH_CHANNEL_NAMES
from ..formats.table import format_for, format_of, skeleton_for, states_unit
from ..model import units
from ..model.motion import Motion
from ..model.rig import body_reason, body_view
from ..model.skeleton import TRANSLATIONS
from .takes import add_take_options, take_of
from .verb import Verb

SET_UNIT = f"set another with --unit UNIT (Python: unit=UNIT), UNIT: {units.UNIT_HELP}"
_WORDS = {"m": "metres", "cm": "centimetres", "mm": "millimetres", "in": "inches"}
SET_RATE = "set it with --frame-rate HZ (Python: read_amc(..., frame_rate=HZ))"


def describe(
    motion: Motion,
    source: str | os.PathLike | None = None,
    skeleton_file: str | os.PathLike | None = None,
    *,
    frame_rate_given: bool = False,
) -> dict[str, Any]:
    """A take's facts as a dict ready for JSON (see :func:`as_text` for their meaning).

    ``source`` and ``skeleton_file`` name the files it came from;
    ``frame_rate_given`` says that an AMC's rate came from the caller
    (without it, an AMC whose header states no rate is said to be at the
    assumed 120 Hz).  Lengths are in the skeleton's length unit and in
    metres, angles in its angle unit; ranges are (min, max) over the frames,
    NaN ignored, None where there is no number.
    """
    skeleton = motion.skeleton
    bvh = skeleton.convention == "bvh"
    meters = skeleton.meters_per_unit
    sizing = skeleton.sizing()
    up = take_up(motion)
    axis = up.axis.lstrip("-")
    first = motion.positions()[0] if motion.frames else None
    lows, highs = _ranges(motion.values)
    joints, depths = [], _depths(skeleton)
    for name in ("root", *skeleton.bone_names):
        bone = None if name == "root" else skeleton.bone(name)
        start = skeleton.first_column(name)
        channels = [
            {
                "name": BVH_CHANNEL_NAMES[dof] if bvh else dof,
                "dof": dof,
                "column": start + i,
                "min": lows[start + i],
                "max": highs[start + i],
                "unit": skeleton.angle_unit if dof[0] == "r" else units.label(skeleton.length_unit),
            }
            for i, dof in enumerate(skeleton.dofs(name))
        ]
        joints.append(
            {
                "name": skeleton.root.name if name == "root" else name,
                "parent": None if name == "root" else _point_name(skeleton, skeleton.parent(name)),
                "kind": "root" if bone is None else "end site" if bone.end_site else "joint" if bvh else "bone",
                "depth": depths[name],
                "channels": channels,
            }
        )
    rate_stated = any("samples-per-second" in line.lower() for line in motion.header)
    return {
        "file": None if source is None else os.fspath(source),
        "skeleton_file": None if skeleton_file is None else os.fspath(skeleton_file),
        "format": (kind := format_for(skeleton.convention) if source is None else format_of(source)).name,
        "takes": kind.takes(source) if source is not None and kind.takes is not None else None,
        "frames": motion.frames,
        "first_frame": motion.first_frame,
        "last_frame": motion.last_frame,
        "frame_rate": motion.frame_rate,
        "frame_rate_source": "stated" if bvh or rate_stated else "given" if frame_rate_given else "assumed",
        "duration": motion.frames / motion.frame_rate,
        "angle_unit": skeleton.angle_unit,
        "length_unit": {
            "text": skeleton.length_unit,
            "label": units.label(skeleton.length_unit),
            "meters_per_unit": meters,
            "source": skeleton.length_source,
            "why": _why(skeleton, sizing),
            "how_to_set": SET_UNIT,
        },
        "up_axis": up.axis,
        "up_reason": up.reason,
        "forward": (facing := take_forward(motion, up)).axis,
        "forward_reason": facing.reason,
        "body": _body(motion),
        "rest_pose": {
            "extents": list(sizing.extents),
            "extents_m": [e * meters for e in sizing.extents],
            "height": sizing.extents["xyz".index(axis)],
            "height_m": sizing.extents["xyz".index(axis)] * meters,
            "from_poses": skeleton.posed is not None,  # the rest pose stands no figure: the frames' median
        },
        "first_frame_height": None if first is None else _clean(_extent(first, axis)),
        "first_frame_height_m": None if first is None else _clean(_extent(first, axis) * meters),
        "channels": len(skeleton.channels),
        "joints": joints,
    }


def as_text(facts: dict[str, Any]) -> str:
    """The facts of :func:`describe` in words, for a person new to the take (and to mocap)."""
    unit = facts["length_unit"]
    label, meters = unit["label"], unit["meters_per_unit"]
    rest = facts["rest_pose"]
    frames, rate = facts["frames"], facts["frame_rate"]
    skeleton_file = f" of skeleton {facts['skeleton_file']}" if facts["skeleton_file"] else ""
    lines = [f"{facts['file'] or 'take'}: {facts['format']} take{skeleton_file}"]
    if frames:
        span = f"{frames} frame{'s' if frames > 1 else ''}, numbered {facts['first_frame']} to {facts['last_frame']}"
    else:
        span = f"no frames (the first would be number {facts['first_frame']})"
    rate_note = {"stated": "", "given": " (given)", "assumed": f" (assumed: the AMC states no rate; {SET_RATE})"}
    field(
        lines, "frames", f"{span}, at {rate:.6g} Hz{rate_note[facts['frame_rate_source']]}: {facts['duration']:.6g} s"
    )
    takes = facts["takes"]
    if takes and len(takes) > 1:
        others = ", ".join(takes[1:])
        field(
            lines,
            "takes",
            f"{len(takes)} in the file; this is the first, {takes[0]}; the others: {others} "
            "(Python: mt.read_gltf(path, animation=NAME))",
        )
    unit_name = label if label == "m" else f"{label} = {_g(meters)} m"
    field(lines, "length unit", f"{unit_name}, {unit['source']}: {unit['why']}. {SET_UNIT[0].upper()}{SET_UNIT[1:]}")
    field(lines, "up axis", f"{facts['up_axis']}: {facts['up_reason']}. Set another with --up AXIS where a verb has it")
    field(lines, "facing", f"{facts['forward'] or 'not told'}: {facts['forward_reason']}")
    body = facts["body"]
    field(lines, "body", f"{body['joint']}: {body['why']}")
    if body["offset_channels"]:
        field(
            lines,
            "offsets",
            f"{body['offset_channels']} position channels of {body['offset_joints']} joints below it only hold "
            "their OFFSET (constant over the take): steps treat them as offsets and write them back as found",
        )
    pose = "the frames' poses (median)" if rest["from_poses"] else "the rest pose"
    height = f"{_g(rest['height_m'])} m = {_g(rest['height'])} {label} in {pose}"
    if facts["first_frame_height"] is not None:
        height += f", {_g(facts['first_frame_height_m'])} m = {_g(facts['first_frame_height'])} {label} in frame 1"
    field(lines, "height", f"{height} (the extent along {facts['up_axis'].lstrip('-')})")
    extents = " x ".join(_g(e) for e in rest["extents"])
    if rest["from_poses"]:
        field(lines, "poses", f"{extents} {label} along x, y, z (median; the rest pose stands no figure)")
    else:
        field(lines, "rest pose", f"{extents} {label} along x, y, z")
    joints = facts["joints"]
    counted = sum(1 for j in joints if j["kind"] != "end site")
    sites = f", {len(joints) - counted} end sites" if len(joints) > counted else ""
    angle = "degrees" if facts["angle_unit"] == "deg" else "radians"
    field(lines, "joints", f"{counted} (the root included){sites}; {facts['channels']} channels, angles in {angle}")
    lines += ["", f"Joint tree, each channel with its range over the take (min .. max; lengths in {label}):"]
    width = max((len(_indent(j["depth"])) + 2 + len(c["name"]) for j in joints for c in j["channels"]), default=0)
    for joint in joints:
        pad = _indent(joint["depth"])
        kind = (
            " (end site)"
            if joint["kind"] == "end site"
            else " (root)"
            if joint["name"] != "root" == joint["kind"]
            else ""
        )
        empty = " (no channels)" if not joint["channels"] and joint["kind"] != "end site" else ""
        lines.append(f"  {pad}{joint['name']}{kind}{empty}")
        for c in joint["channels"]:
            name = f"{pad}  {c['name']}"
            low, high = _span(c["min"], c["max"])
            lines.append(f"  {name:<{width}}  {low:>11} .. {high:<11} {c['unit']}")
    return "\n".join(lines)


DEEPEST = 24  # levels indented; deeper joints say their depth (a long chain would be all spaces)


def _indent(depth: int) -> str:
    return "  " * depth if depth <= DEEPEST else "  " * DEEPEST + f"[{depth}] "


def field(lines: list[str], name: str, text: str) -> None:
    """Append ``name`` and ``text`` to ``lines``, wrapped at 100 columns under a 15-column margin."""
    lines.extend(textwrap.wrap(text, 100, initial_indent=f"  {name:<13}", subsequent_indent=" " * 15))


def unit_notes(motion: Motion, result: Motion, target: str | os.PathLike) -> list[str]:
    """What a command says about length units after writing ``result`` (made from ``motion``)
    to ``target``.  A BVH file states no unit: one written in a unit its size does not tell
    must be read back with ``--unit``.  Into other files (an ASF's ``:units length``, positions)
    the unit goes as a fact: if the input's was only assumed, that is said."""
    if not states_unit(target):
        unit = result.skeleton.length_unit or "1"
        told = result.skeleton.sizing().unit or units.ASSUMED_UNIT
        if units.meters_per(unit) == units.meters_per(told):
            return []
        return [
            f"note: BVH files state no length unit and the size of this one does not tell its unit, "
            f"{units.label(unit)} ({_g(units.meters_per(unit))} m): read {os.fspath(target)} with --unit {unit}"
        ]
    if motion.skeleton.length_source == "assumed":
        return [
            f"note: the length unit of the input was assumed ({units.label(motion.skeleton.length_unit)}): "
            f"its size tells none; {SET_UNIT}"
        ]
    return []


def _why(skeleton, sizing: units.Sizing) -> str:
    """Why the skeleton has its length unit, in words."""
    source, unit = skeleton.length_source, units.label(skeleton.length_unit)
    if source == "given":
        return "given by the caller"
    if source == "stated" and skeleton.convention == "asf":
        return f"the skeleton says so (:units length {skeleton.unit('length')})"
    if source == "stated":
        return "its file states it (glTF is in metres)"
    if source == "default":
        return "the Acclaim default: the ASF has no :units length"
    low, high = units.HUMAN_HEIGHT
    if source == "detected":
        meters = sizing.told_by * skeleton.meters_per_unit
        what = f"stands {_g(sizing.told_by)} units tall along {sizing.up}"
        if sizing.axis != sizing.up:
            what = (
                f"is {_g(sizing.height)} units tall along {sizing.up} but {_g(sizing.told_by)} wide along {sizing.axis}"
            )
        said = ""
        if skeleton.unit("length") is not None:
            stated = units.meters_per(skeleton.unit("length"))
            said = (
                f"the skeleton states :units length {skeleton.unit('length')}, which makes it "
                f"{_g(max(sizing.extents) * stated)} m in size; "
            )
        pose = "its poses stand" if skeleton.posed is not None else "its rest pose"
        if skeleton.posed is not None:
            what = what.replace("stands ", "", 1)
        if skeleton.length_unit == units.ACCLAIM_CMU:
            return (
                f"{said}{pose} {what}, {_g(meters)} m in CMU's inch/0.45: its joints are named as in CMU's BVH "
                f"conversion (LHipJoint, RHipJoint), which keeps the CMU ASF's unit, and none of "
                f"{', '.join(units.DETECTABLE)} gives a human size ({low:g} to {high:g} m)"
            )
        return (
            f"{said}{pose} {what}, {_g(meters)} m in {_WORDS.get(unit, unit)}, the one unit of "
            f"{', '.join(units.DETECTABLE)} that gives a human size ({low:g} to {high:g} m)"
        )
    return (
        f"no unit of {', '.join(units.DETECTABLE)} makes the rest pose ({_g(sizing.height)} units tall along "
        f"{sizing.up}, {_g(max(sizing.extents))} at most) a human size ({low:g} to {high:g} m), so {unit}, "
        f"the unit of most BVH files, is assumed"
    )


def _body(motion: Motion) -> dict[str, Any]:
    """Which joint carries the body and why; which joints above it stand still, and how many
    position channels below it only hold offsets (:mod:`motiontheater.model.rig`)."""
    skeleton = motion.skeleton
    view = body_view(motion)
    kept = set(view.columns.tolist())
    above = view.still_above
    offsets = [
        (joint, column)
        for joint in skeleton.bone_names
        if joint != view.body and joint not in above
        for column, dof in zip(motion.columns(joint), skeleton.dofs(joint))
        if dof in TRANSLATIONS and column not in kept
    ]
    name = skeleton.root.name if view.body == "root" else view.body
    why = body_reason(view)
    return {
        "joint": name,
        "why": why,
        "static_joints": [skeleton.root.name if j == "root" else j for j in above],
        "offset_channels": len(offsets),
        "offset_joints": len({j for j, _ in offsets}),
    }


def _ranges(values: np.ndarray) -> tuple[list[float | None], list[float | None]]:
    """Per column (min, max) over the frames, NaN ignored; None where a column has no number."""
    if not values.shape[0]:
        return [None] * values.shape[1], [None] * values.shape[1]
    finite = np.isfinite(values)
    lows = np.where(finite, values, np.inf).min(axis=0)
    highs = np.where(finite, values, -np.inf).max(axis=0)
    return [_clean(v) for v in lows], [_clean(v) for v in highs]


def _clean(value: float) -> float | None:
    value = float(value)
    return value if math.isfinite(value) else None


def _extent(points: np.ndarray, axis: str) -> float:
    along = points[:, "xyz".index(axis)]
    along = along[np.isfinite(along)]
    return float(along.max() - along.min()) if len(along) else math.nan


def _point_name(skeleton, joint: str) -> str:
    return skeleton.root.name if joint == "root" else joint


def _depths(skeleton) -> dict[str, int]:
    """Each joint's depth below the root, in one walk (a 10,000-level chain is read in a blink)."""
    depths = {"root": 0}
    for name in skeleton.bone_names:
        path = []
        while name not in depths:
            path.append(name)
            name = skeleton.parent(name)
        for joint in reversed(path):
            depths[joint] = depths[name] + 1
            name = joint
    return depths


def _g(value: float | None) -> str:
    """A number for people: 4 significant digits, "-" for none."""
    return "-" if value is None else f"{value:.4g}"


def _span(low: float | None, high: float | None) -> tuple[str, str]:
    """A range for people: both ends with the decimals that give the larger about 5 digits."""
    if low is None or high is None:
        return "-", "-"
    size = max(abs(low), abs(high))
    decimals = min(6, max(0, 4 - math.floor(math.log10(size)))) if size > 0 else 0
    return f"{round(low, decimals) + 0.0:.{decimals}f}", f"{round(high, decimals) + 0.0:.{decimals}f}"


def _arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("input", metavar="TAKE", help="the AMC or BVH take")
    parser.add_argument("--json", action="store_true", help="print JSON (NaN as null)")
    add_take_options(parser)


def _info(args: argparse.Namespace) -> int:
    import json

    motion = take_of(args, args.input)
    skeleton_file = skeleton_for(args.input, args.asf)
    facts = describe(motion, args.input, skeleton_file, frame_rate_given=args.frame_rate is not None)
    print(json.dumps(facts, indent=2) if args.json else as_text(facts))
    return 0


INFO = Verb(
    "info",
    "describe a take: frames, rate, units, height, up axis, joint tree and channel ranges",
    _arguments,
    _info,
    description=(
        "Describe a take (AMC or BVH): its frames, frame rate, duration and first frame; its length "
        "unit, how that was chosen (stated by the ASF, detected from the character's size, given with "
        "--unit, or assumed) and how to set another; the character's height in metres and in file "
        "units and its up axis; and the joint tree with each channel's range over the take. --json "
        "prints the same as JSON for programs."
    ),
    epilog="Example: motiontheater info 01_01.bvh\nExample: motiontheater info 01_01.amc --json",
)
