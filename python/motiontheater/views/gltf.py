"""glTF 2.0 out (``.glb`` binary, ``.gltf`` text with its buffer inside): a node per joint with
its rest transform, a skin with inverse bind matrices, optionally a body of capsules skinned to
it, and an animation per take.

The layout follows the specification's rules: every accessor in a buffer view of its own at a
multiple of 4 bytes, min and max on positions and key times, quaternions of unit length
(x, y, z, w), metres, +Y up, +Z forward (see :mod:`.armature`).  An animation's extras keep the
take's frame rate and first frame number, so that :func:`~.gltf_read.read_gltf` gives the take
back exactly as it was timed.
"""

from __future__ import annotations

import base64
import json
import os
import struct
from collections.abc import Sequence
from typing import Any

import numpy as np

from .._io import Source, output
from .._version import __version__
from ..formats.gltf_read import GLB_BIN, GLB_JSON, GLB_MAGIC
from ..model.motion import Motion
from .armature import Armature, Track, animated
from .capsules import capsules

FLOAT, UNSIGNED_SHORT, UNSIGNED_INT = 5126, 5123, 5125
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963
TYPES = {1: "SCALAR", 3: "VEC3", 4: "VEC4", 16: "MAT4"}


class _Buffer:
    """The binary buffer and the JSON's bufferViews and accessors that describe it."""

    def __init__(self) -> None:
        self.parts: list[memoryview] = []
        self.size = 0
        self.views: list[dict[str, Any]] = []
        self.accessors: list[dict[str, Any]] = []

    def add(self, array: np.ndarray, *, target: int | None = None, bounds: bool = False) -> int:
        """An accessor of ``array`` (float32, uint16 or uint32; last axis the components), its
        index."""
        array = np.ascontiguousarray(array)
        kind = {np.dtype(np.float32): FLOAT, np.dtype(np.uint16): UNSIGNED_SHORT, np.dtype(np.uint32): UNSIGNED_INT}
        width = 1 if array.ndim == 1 else int(np.prod(array.shape[1:]))
        view: dict[str, Any] = {"buffer": 0, "byteOffset": self.size, "byteLength": array.nbytes}
        if target is not None:
            view["target"] = target
        self.views.append(view)
        self._append(array.data.cast("B"))
        accessor: dict[str, Any] = {
            "bufferView": len(self.views) - 1,
            "componentType": kind[array.dtype],
            "count": len(array),
            "type": TYPES[width],
        }
        if bounds:
            flat = array.reshape(len(array), width)
            accessor["min"] = [_number(x) for x in flat.min(axis=0)]
            accessor["max"] = [_number(x) for x in flat.max(axis=0)]
        self.accessors.append(accessor)
        return len(self.accessors) - 1

    def _append(self, data: memoryview) -> None:
        self.parts.append(data)
        self.size += len(data)
        if self.size % 4:
            self.parts.append(memoryview(bytes(4 - self.size % 4)))
            self.size += 4 - self.size % 4


def _number(x: Any) -> float | int:
    return int(x) if isinstance(x, np.integer) else float(x)


def node_names(armature: Armature) -> list[str]:
    """The armature's names as glTF nodes: "root" (every ASF skeleton's) becomes "Root", since
    three.js binds an animation track of a node named "root" to the scene itself."""
    names: list[str] = []
    for name in armature.names:
        found, n = ("Root" if name == "root" else name), 2
        while found in names or (found != name and found in armature.names):
            found, n = f"Root{n}", n + 1
        names.append(found)
    return names


def _nodes(armature: Armature) -> list[dict[str, Any]]:
    nodes: list[dict[str, Any]] = []
    for n, name in enumerate(node_names(armature)):
        node: dict[str, Any] = {"name": name}
        children = armature.children(n).tolist()
        if children:
            node["children"] = children
        if np.any(armature.translations[n]):
            node["translation"] = [float(x) for x in armature.translations[n]]
        if not np.allclose(armature.rotations[n], (0, 0, 0, 1), rtol=0, atol=1e-15):
            node["rotation"] = [float(x) for x in armature.rotations[n]]
        nodes.append(node)
    return nodes


def _animation(buffer: _Buffer, armature: Armature, track: Track) -> dict[str, Any]:
    times = (np.arange(track.frames) / track.frame_rate).astype(np.float32)
    keys = buffer.add(times, bounds=True)
    samplers, channels = [], []
    for path, nodes, values in (
        ("rotation", armature.turning, track.rotations),
        ("translation", armature.moving, track.translations),
    ):
        for node, series in zip(nodes.tolist(), values):
            samplers.append({"input": keys, "output": buffer.add(series), "interpolation": "LINEAR"})
            channels.append({"sampler": len(samplers) - 1, "target": {"node": node, "path": path}})
    return {
        "name": track.name,
        "samplers": samplers,
        "channels": channels,
        "extras": {"frame_rate": track.frame_rate, "first_frame": track.first_frame},
    }


def _body(buffer: _Buffer, armature: Armature) -> dict[str, Any]:
    body = capsules(armature)
    joints = np.zeros((len(body.nodes), 4), np.uint16)
    joints[:, 0] = body.nodes
    weights = np.zeros((len(body.nodes), 4), np.float32)
    weights[:, 0] = 1.0
    attributes = {
        "POSITION": buffer.add(body.positions, target=ARRAY_BUFFER, bounds=True),
        "NORMAL": buffer.add(body.normals, target=ARRAY_BUFFER),
        "JOINTS_0": buffer.add(joints, target=ARRAY_BUFFER),
        "WEIGHTS_0": buffer.add(weights, target=ARRAY_BUFFER),
    }
    indices = buffer.add(body.triangles.reshape(-1).astype(np.uint32), target=ELEMENT_ARRAY_BUFFER)
    return {"name": "body", "primitives": [{"attributes": attributes, "indices": indices, "material": 0}]}


def gltf_document(
    motions: Motion | Sequence[Motion], *, body: bool = True, names: Sequence[str] | None = None
) -> tuple[dict[str, Any], _Buffer]:
    """The JSON document and binary buffer of the takes (see :func:`write_gltf`)."""
    armature, tracks = animated(motions, names)
    buffer = _Buffer()
    nodes = _nodes(armature)
    inverse_bind = buffer.add(armature.inverse_bind.transpose(0, 2, 1).reshape(-1, 16).astype(np.float32))
    skin = {"name": armature.skeleton.name or "skeleton", "joints": list(range(armature.nodes)), "skeleton": 0}
    skin["inverseBindMatrices"] = inverse_bind
    document: dict[str, Any] = {
        "asset": {
            "version": "2.0",
            "generator": f"motiontheater {__version__}",
            "extras": {
                "up": armature.up,
                "forward": armature.forward,
                "meters_per_unit": armature.scale,
            },
        },
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": nodes,
        "skins": [skin],
    }
    if body:
        document["meshes"] = [_body(buffer, armature)]
        document["materials"] = [
            {"name": "body", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.75, 0.7, 1.0], "metallicFactor": 0.0}}
        ]
        nodes.append({"name": "body", "mesh": 0, "skin": 0})
        document["scenes"][0]["nodes"].append(len(nodes) - 1)
    document["animations"] = [_animation(buffer, armature, track) for track in tracks]
    return document, buffer


def write_gltf(
    motions: Motion | Sequence[Motion],
    target: Source,
    *,
    body: bool = True,
    binary: bool | None = None,
    names: Sequence[str] | None = None,
) -> None:
    """Write takes of one skeleton as glTF 2.0, an animation per take (named ``names``, default
    after their files): binary (GLB) where ``binary`` or the target ends in ``.glb``, else a
    ``.gltf`` holding its buffer as a data URI.  ``body``: a capsule along each bone, skinned,
    so that viewers draw a figure.  A path is written atomically.  ValueError for takes of
    different skeletons, NaN or inf values, a skeleton of one joint or a name that is not text."""
    if binary is None:
        binary = not isinstance(target, (str, os.PathLike)) or os.fspath(target).lower().endswith(".glb")
    document, buffer = gltf_document(motions, body=body, names=names)
    document["buffers"] = [{"byteLength": buffer.size}]
    document["bufferViews"] = buffer.views
    document["accessors"] = buffer.accessors
    if not binary:
        data = base64.b64encode(b"".join(buffer.parts)).decode("ascii")
        document["buffers"][0]["uri"] = "data:application/octet-stream;base64," + data
        with output(target) as f:
            f.write(json.dumps(document, ensure_ascii=False, indent=1).encode("utf-8"))
        return
    text = json.dumps(document, ensure_ascii=False, separators=(",", ":")).encode("utf-8")
    text += b" " * (-len(text) % 4)
    total = 12 + 8 + len(text) + 8 + buffer.size
    with output(target) as f:
        f.write(struct.pack("<III", GLB_MAGIC, 2, total))
        f.write(struct.pack("<II", len(text), GLB_JSON))
        f.write(text)
        f.write(struct.pack("<II", buffer.size, GLB_BIN))
        for part in buffer.parts:
            f.write(part)
