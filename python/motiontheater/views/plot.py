"""Channel curves of motions, before and after, as figures: the MotionTheater thesis's figures
4.26-4.39 (a filter's input and output over frames).  Needs matplotlib (the ``plot`` extra).

One panel per channel of the chosen joints, frames along x, the first take
drawn in black and each compared take in a colour over it, aligned in time
from each take's first frame.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from .._io import Source, output
from .._optional import require
from ..formats.bvh import NAMES as BVH_CHANNELS
from ..model.motion import Motion
from ..model.skeleton import ROTATIONS
from .positions import length_unit_name

if TYPE_CHECKING:
    from matplotlib.figure import Figure

FORMATS = ("png", "svg", "pdf")
MAX_PANELS = 48
_COLOURS = ("#d62728", "#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf")


def figure(
    takes: Sequence[Motion],
    *,
    joints: Sequence[str],
    names: Sequence[str] | None = None,
    dofs: Sequence[str] | None = None,
    frames: tuple[int, int] | None = None,
    width: float = 8.0,
    panel_height: float = 1.8,
    title: str | None = None,
) -> Figure:
    """A matplotlib Figure of the channel curves (see the module docstring).

    ``joints`` names the joints ("root" and bone names) whose channels are
    drawn, ``dofs`` limits them to some dofs ("rx", "tz", ...; all by
    default), ``frames`` (first, last) limits x to those frame numbers of
    the first take.  Width and panel height are in inches.  Angles are in
    the skeleton's unit, lengths in file units (named where the unit has a
    name).  ValueError for an empty choice or a bad range;
    UnknownNameError for a joint or dof the first take lacks.
    """
    require("matplotlib", "plot", "plotting curves")
    from matplotlib.figure import Figure

    if not takes:
        raise ValueError("give at least one take to plot")
    if not joints:
        raise ValueError("give at least one joint to plot (e.g. --joints lfemur,rfemur)")
    labels = list(names) if names is not None else [f"take {i + 1}" for i in range(len(takes))]
    if len(labels) != len(takes):
        raise ValueError(f"give one name per take ({len(takes)}), got {len(labels)}")
    base = takes[0]
    panels: list[tuple[str, str]] = []
    for joint in joints:
        available = base.skeleton.dofs(joint)
        chosen = available if dofs is None else tuple(d for d in (x.lower() for x in dofs) if d in available)
        if not chosen:
            what = "no channels" if not available else f"none of the dofs {', '.join(dofs or ())}"
            raise ValueError(f"joint '{joint}' has {what} to plot")
        panels.extend((joint, dof) for dof in chosen)
    if len(panels) > MAX_PANELS:
        raise ValueError(f"{len(panels)} channels make too many panels (at most {MAX_PANELS}): choose fewer joints")
    first, last = base.first_frame, base.first_frame + base.frames - 1
    lo, hi = frames if frames is not None else (first, last)
    if not (first <= lo < hi <= last):
        raise ValueError(f"frames {lo}..{hi} must lie within the take's frames {first}..{last}, first < last")

    fig = Figure(figsize=(width, 0.9 + panel_height * len(panels)), layout="constrained")
    axes = fig.subplots(len(panels), 1, sharex=True, squeeze=False)[:, 0]
    for ax, (joint, dof) in zip(axes, panels):
        for k, (motion, label) in enumerate(zip(takes, labels)):
            if not motion.skeleton.has_joint(joint) or dof not in motion.skeleton.dofs(joint):
                continue
            # frame numbers of the first take at the same time from each take's start
            x = base.first_frame + np.arange(motion.frames) * (base.frame_rate / motion.frame_rate)
            shown = (x >= lo) & (x <= hi)
            ax.plot(
                x[shown],
                motion.channel(joint, dof)[shown],
                color="black" if k == 0 else _COLOURS[(k - 1) % len(_COLOURS)],
                linewidth=1.0 if k == 0 else 1.3,
                label=label,
            )
        spelled = BVH_CHANNELS[dof] if base.skeleton.convention == "bvh" else dof  # as the file names it
        ax.set_ylabel(f"{joint} {spelled}\n({_unit(base, dof)})", fontsize=9)
        ax.grid(True, color="0.9", linewidth=0.6)
        ax.tick_params(labelsize=8)
        ax.set_xlim(lo, hi)
    axes[-1].set_xlabel(f"frame ({base.frame_rate:g} Hz)", fontsize=9)
    if len(takes) > 1:
        axes[0].legend(fontsize=8, loc="upper right", frameon=False, ncols=len(takes))
    fig.suptitle(title if title is not None else " vs ".join(labels), fontsize=10)
    return fig


def _unit(motion: Motion, dof: str) -> str:
    if dof in ROTATIONS:
        return "degrees" if motion.skeleton.angle_unit == "deg" else "radians"
    return length_unit_name(motion, False) or "file units"


def plot(takes: Sequence[Motion], target: Source, *, format: str | None = None, dpi: float = 150.0, **options) -> None:
    """Write :func:`figure` (same options) as PNG, SVG or PDF (``format``, default the target's
    suffix) at ``dpi`` dots per inch (PNG).  A path is written atomically."""
    if format is None:
        suffix = os.path.splitext(os.fspath(target) if isinstance(target, (str, os.PathLike)) else "")[1]
        format = suffix.lstrip(".").lower()
    if format not in FORMATS:
        raise ValueError(f"format must be one of {', '.join(FORMATS)} (or a target ending in one), got {format!r}")
    fig = figure(takes, **options)
    # no creation date: the same curves give the same file
    metadata = {"Date": None} if format == "svg" else {"CreationDate": None} if format == "pdf" else None
    with output(target) as f:
        fig.savefig(f, format=format, dpi=dpi, metadata=metadata)
