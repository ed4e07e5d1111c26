"""Joint positions out: CSV, NumPy .npz and TRC (the marker format of OpenSim)."""

from __future__ import annotations

import os
import typing
from typing import Annotated, Literal

import numpy as np

from .._io import Source, output
from ..model import units
from ..model.motion import Motion
from ..model.registry import exporter

FORMATS = ("csv", "npz", "trc")


def length_unit_name(motion: Motion, meters: bool) -> str | None:
    """ "m" with meters, else the name of the skeleton's unit (its length unit in effect: a
    BVH's detected, given or assumed one, a converted motion's carried one) if it has one:
    m, cm, mm or in; None for the Acclaim convention's inch / L units of CMU and HDM05."""
    return "m" if meters else units.named(motion.skeleton.length_unit)


def length_unit_label(motion: Motion, meters: bool) -> str:
    """The unit of exported lengths for headers: "m" with meters, else the skeleton's unit,
    named (m, cm, mm, in) or "in/L" for an Acclaim unit inch / L (CMU and HDM05: "in/0.45")."""
    return "m" if meters else units.label(motion.skeleton.length_unit)


@exporter("positions", (".csv", ".npz", ".trc"), "write every joint's world position per frame (CSV, NPZ or TRC)")
def write_positions(
    motion: Motion,
    target: Source,
    *,
    meters: Annotated[bool, "lengths in metres rather than the skeleton's units"] = False,
    format: Annotated[Literal["csv", "npz", "trc"] | None, "file format (default: from the suffix)"] = None,
    workers: Annotated[int | None, "threads (default: every core for large takes)"] = None,
) -> str:
    """Write the world position of every joint per frame (``Motion.positions()``) to a file.

    The format is the target's suffix unless given.  CSV: one row per frame,
    columns ``frame``, ``time [s]``, ``<joint>.x [<unit>]``, ``<joint>.y
    [<unit>]``, ``<joint>.z [<unit>]`` in the skeleton's joint order (the
    root under its file's name: root, or a BVH's Hips), 10
    significant digits, the unit as :func:`length_unit_label` gives it (m,
    cm, mm, in, or in/0.45 for CMU and HDM05 units).  NPZ: positions
    (frames, joints, 3) exact, joint_names, frames, times, frame_rate,
    meters_per_unit, length_unit.  TRC (OpenSim markers) needs a named unit
    (m, cm, mm, in): write CMU and HDM05 in metres.  Lengths are in the
    skeleton's length unit (a BVH's detected, given or assumed one:
    ``skeleton.length_source``), or in metres.  A path is written
    atomically.  Returns the format written.
    """
    if format is None:
        suffix = os.path.splitext(os.fspath(target) if isinstance(target, (str, os.PathLike)) else "")[1]
        format = typing.cast(Literal["csv", "npz", "trc"], suffix.lstrip(".").lower())
    if format not in FORMATS:
        raise ValueError(f"format must be one of {', '.join(FORMATS)} (or a target ending in one), got {format!r}")
    unit = length_unit_name(motion, meters)
    if format == "trc" and unit is None:
        raise ValueError(
            f"TRC needs a named length unit, and this skeleton's unit is "
            f"{motion.skeleton.meters_per_unit:.6g} m: write it in metres (meters=True, --meters)"
        )
    positions = motion.positions(meters=meters, workers=workers)
    frames = motion.first_frame + np.arange(motion.frames)
    names = motion.skeleton.point_names  # a BVH's root under its own name (Hips), as bvh-toolbox writes it
    with output(target) as f:
        if format == "npz":
            np.savez(
                f,
                positions=positions,
                joint_names=np.array(names),
                frames=frames,
                times=motion.times,
                frame_rate=motion.frame_rate,
                meters_per_unit=1.0 if meters else motion.skeleton.meters_per_unit,
                length_unit=length_unit_label(motion, meters),
            )
        else:
            table = np.column_stack([frames, motion.times, positions.reshape(motion.frames, -1)])
            fmt = ["%d", "%.10g"] + ["%.10g"] * (3 * len(names))
            if format == "csv":
                label = length_unit_label(motion, meters)
                header = ",".join(["frame", "time [s]", *(f"{n}.{a} [{label}]" for n in names for a in "xyz")])
                np.savetxt(f, table, delimiter=",", fmt=fmt, header=header, comments="", encoding="utf-8")
            else:
                assert unit is not None  # refused above
                f.write(_trc_header(motion, names, unit, target).encode())
                np.savetxt(f, table, delimiter="\t", fmt=fmt, encoding="utf-8")
    return format


def _trc_header(motion: Motion, names, unit: str, target) -> str:
    rate = f"{motion.frame_rate:g}"
    name = os.path.basename(os.fspath(target)) if isinstance(target, (str, os.PathLike)) else "positions.trc"
    markers = "\t".join(f"{n}\t\t" for n in names)
    axes = "\t".join(f"X{i}\tY{i}\tZ{i}" for i in range(1, len(names) + 1))
    return (
        f"PathFileType\t4\t(X/Y/Z)\t{name}\n"
        "DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\tOrigDataStartFrame\tOrigNumFrames\n"
        f"{rate}\t{rate}\t{motion.frames}\t{len(names)}\t{unit}\t{rate}\t{motion.first_frame}\t{motion.frames}\n"
        f"Frame#\tTime\t{markers}\n"
        f"\t\t{axes}\n"
        "\n"
    )
