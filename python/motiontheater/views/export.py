"""The ``export`` exporter: takes of one skeleton into the formats animation tools read (glTF/GLB,
USD and FBX, each a writer module of its own), chosen by the target's suffix.  One registry entry, so
that it is at once ``motiontheater export a.amc b.bvh -o both.glb``, a recipe's last step and a
batch step that converts a whole database."""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from functools import partial
from typing import Annotated, Literal

from .._io import Source
from ..model.motion import Motion
from ..model.registry import exporter
from .fbx import write_fbx
from .gltf import write_gltf
from .usd import write_usd

Kind = Literal["glb", "gltf", "usd", "usda", "usdc", "fbx"]
WRITERS: dict[str, Callable[..., None]] = {
    "glb": partial(write_gltf, binary=True),
    "gltf": partial(write_gltf, binary=False),
    "usd": partial(write_usd, binary=True),  # the crate, as OpenUSD writes a .usd
    "usda": partial(write_usd, binary=False),
    "usdc": partial(write_usd, binary=True),
    "fbx": write_fbx,
}


@exporter(
    "export",
    (".glb", ".gltf", ".usd", ".usda", ".usdc", ".fbx"),
    "write takes as glTF/GLB, USD or FBX for Blender, three.js, game engines and USD pipelines: "
    "skeleton, skin and animation",
    several=True,
)
def export(
    motions: Motion | Sequence[Motion],
    target: Source,
    *,
    mesh: Annotated[bool, "a body of capsules along the bones, skinned, so that viewers draw a figure"] = True,
    rate: Annotated[float | None, "frames per second to resample every take to (default: each take's own)"] = None,
    format: Annotated[Kind | None, "file format (default: from the suffix)"] = None,
) -> str:
    """Write takes of one skeleton into one file, an animation per take, named after their files:
    glTF 2.0 (``.glb`` binary, ``.gltf`` text), USD's UsdSkel (``.usdc`` or ``.usd`` binary,
    ``.usda`` text; needs usd-core; several takes are the variants of a variant set ``take``) or
    binary FBX 7.4 (``.fbx``; an animation stack per take).

    The skeleton is a node per joint at its rest pose (the calibration pose; an ASF bone's node
    at its start, a leaf's end as a node of its own) with a skin; each take's animation turns
    every joint and moves the root (and any joint whose position channels move) at every frame,
    at the take's own rate, so that a reader draws every joint where motiontheater's forward
    kinematics puts it.  Lengths are metres (in FBX centimetres, its own unit, stated in the
    file), +Y is up and the take faces +Z, whatever the take's unit and up axis (a z-up export
    is stood up, a take in inches scaled).  The format is the target's suffix unless given.  A path is written atomically.  Returns the format written.
    """
    if format is None:
        suffix = os.path.splitext(os.fspath(target) if isinstance(target, (str, os.PathLike)) else "")[1]
        format = suffix.lstrip(".").lower() or None  # type: ignore[assignment]
        if format is None:
            raise ValueError("give the format (format=...) when writing to a file object")
    takes = [motions] if isinstance(motions, Motion) else list(motions)
    if rate is not None:
        takes = [t if t.frame_rate == rate else t.resample(rate=rate) for t in takes]
    if format not in WRITERS:
        raise ValueError(f"format must be one of {', '.join(WRITERS)} (or a target ending in one), got {format!r}")
    WRITERS[format](takes, target, body=mesh)
    return format
