"""glTF 2.0 in (``.glb`` and ``.gltf``): a skin's joints and one of its animations as a BVH
motion, so that ``convert x.glb -o x.bvh`` works.

Each joint becomes a BVH joint whose OFFSET is its rest translation and whose three rotation
channels (Z, X, Y) hold its whole local rotation per frame; a joint whose translation is
animated gets position channels too, and a leaf that nothing animates is an End Site.  Nodes
above the skin's root (an "Armature" node turned or scaled, as Blender exports) are folded into
the root.  Frames are sampled at the animation's own rate (a file of ours states it) or the one
asked for, interpolated as the samplers say (step, linear/slerp, cubic spline).  Lengths are
metres, as glTF states.
"""

from __future__ import annotations

import base64
import json
import struct
import urllib.parse
from pathlib import Path
from typing import Any

import numpy as np

from mtcore.rotations import (
    matrices_to_quaternions,
    quaternions_to_euler,
    quaternions_to_matrices,
    slerp,
    unroll_euler,
)

from .._io import Source, read_source
from ..model.motion import Motion
from ..model.skeleton import Bone, Root, Skeleton, canonical_hierarchy

GLB_MAGIC, GLB_JSON, GLB_BIN = 0x46546C67, 0x4E4F534A, 0x004E4942  # the GLB header's and chunks' tags

COMPONENTS = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16, 5125: np.uint32, 5126: np.float32}
WIDTHS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}
ORDER = ("rz", "rx", "ry")  # BVH's Zrotation Xrotation Yrotation: R = Rz Rx Ry


class _File:
    """A glTF document and its buffers, read as accessors."""

    def __init__(self, source: Source) -> None:
        data, name = read_source(source)
        self.name = name or "glTF"
        self.folder = Path(name).parent if name else Path(".")
        binary = None
        if data[:4] == struct.pack("<I", GLB_MAGIC):
            text, binary = self._chunks(data)
        else:
            text = data
        try:
            self.document = json.loads(text.decode("utf-8"))
        except (UnicodeDecodeError, json.JSONDecodeError) as e:
            raise ValueError(f"{self.name}: not a glTF file (its JSON does not parse: {e})") from None
        if not isinstance(self.document, dict) or not str(self.document.get("asset", {}).get("version", "")).startswith(
            "2"
        ):
            raise ValueError(f"{self.name}: not a glTF 2.0 file (asset.version must be 2.x)")
        self.buffers = [self._buffer(b, binary) for b in self.document.get("buffers", [])]

    def _chunks(self, data: bytes) -> tuple[bytes, bytes | None]:
        if len(data) < 20:
            raise ValueError(f"{self.name}: a GLB file cut short ({len(data)} bytes)")
        _, version, total = struct.unpack_from("<III", data)
        if version != 2:
            raise ValueError(f"{self.name}: GLB version {version}; only version 2 (glTF 2.0) is read")
        text, binary, at = None, None, 12
        while at + 8 <= min(total, len(data)):
            length, kind = struct.unpack_from("<II", data, at)
            chunk = data[at + 8 : at + 8 + length]
            if len(chunk) < length:
                raise ValueError(f"{self.name}: a GLB chunk at byte {at} runs past the end of the file")
            if kind == GLB_JSON and text is None:
                text = chunk
            elif kind == GLB_BIN and binary is None:
                binary = chunk
            at += 8 + length + (-length % 4)
        if text is None:
            raise ValueError(f"{self.name}: the GLB file has no JSON chunk")
        return text, binary

    def _buffer(self, entry: dict[str, Any], binary: bytes | None) -> bytes:
        uri = entry.get("uri")
        if uri is None:
            if binary is None:
                raise ValueError(f"{self.name}: a buffer without a uri, and no GLB binary chunk")
            return binary
        if uri.startswith("data:"):
            head, _, body = uri.partition(",")
            return base64.b64decode(body) if head.endswith(";base64") else urllib.parse.unquote_to_bytes(body)
        path = self.folder / urllib.parse.unquote(uri)
        try:
            return path.read_bytes()
        except OSError as e:
            raise ValueError(f"{self.name}: cannot read its buffer {path}: {e.strerror}") from None

    def accessor(self, index: int) -> np.ndarray:
        """(count, components) float64 values of an accessor, normalized integers scaled."""
        a = self.document["accessors"][index]
        dtype = np.dtype(COMPONENTS[a["componentType"]]).newbyteorder("<")
        width, count = WIDTHS[a["type"]], a["count"]
        out = np.zeros((count, width), dtype)
        if "bufferView" in a:
            view = self.document["bufferViews"][a["bufferView"]]
            data = self.buffers[view.get("buffer", 0)]
            start = view.get("byteOffset", 0) + a.get("byteOffset", 0)
            stride = view.get("byteStride") or width * dtype.itemsize
            end = start + stride * (count - 1) + width * dtype.itemsize if count else start
            if end > len(data) or end > view.get("byteOffset", 0) + view["byteLength"]:
                raise ValueError(f"{self.name}: accessor {index} runs past its buffer view")
            rows = np.ndarray((count, width), dtype, buffer=data, offset=start, strides=(stride, dtype.itemsize))
            out[:] = rows
        if "sparse" in a:
            sparse = a["sparse"]
            at = self._view_array(sparse["indices"], sparse["count"], 1).reshape(-1).astype(np.intp)
            values = self._view_array({**sparse["values"], "componentType": a["componentType"]}, sparse["count"], width)
            out[at] = values
        result = out.astype(np.float64)
        if a.get("normalized") and dtype.kind in "iu":
            info = np.iinfo(dtype)
            result = np.maximum(result / info.max, -1.0)
        return result

    def _view_array(self, part: dict[str, Any], count: int, width: int) -> np.ndarray:
        dtype = np.dtype(COMPONENTS[part["componentType"]]).newbyteorder("<")
        view = self.document["bufferViews"][part["bufferView"]]
        data = self.buffers[view.get("buffer", 0)]
        start = view.get("byteOffset", 0) + part.get("byteOffset", 0)
        return np.frombuffer(data, dtype, count * width, start).reshape(count, width)


def _matrix(node: dict[str, Any]) -> np.ndarray:
    """A node's local transform, 4 x 4 for column vectors."""
    if "matrix" in node:
        return np.array(node["matrix"], float).reshape(4, 4).T
    m = np.eye(4)
    x, y, z, w = node.get("rotation", (0.0, 0.0, 0.0, 1.0))
    m[:3, :3] = quaternions_to_matrices(np.array([[w, x, y, z]], float))[0] * np.array(
        node.get("scale", (1.0, 1.0, 1.0))
    )
    m[:3, 3] = node.get("translation", (0.0, 0.0, 0.0))
    return m


def _split(m: np.ndarray, what: str) -> tuple[float, np.ndarray, np.ndarray]:
    """(uniform scale, rotation 3x3, translation) of a transform; ValueError for a shear or an
    uneven scale, which BVH cannot hold."""
    linear = m[:3, :3]
    scales = np.linalg.norm(linear, axis=0)
    scale = float(scales.mean())
    rotation = linear / scale if scale > 0 else linear
    if not np.allclose(scales, scale, rtol=1e-5) or not np.allclose(rotation.T @ rotation, np.eye(3), atol=1e-5):
        raise ValueError(f"{what} is scaled unevenly or sheared, which a BVH skeleton cannot hold")
    if np.linalg.det(rotation) < 0:
        raise ValueError(f"{what} is mirrored, which a BVH skeleton cannot hold")
    return scale, rotation, m[:3, 3]


def read_gltf(source: Source, *, animation: int | str | None = None, frame_rate: float | None = None) -> Motion:
    """A glTF file's first skin and one of its animations (``animation``: its index or name,
    default the first) as a BVH motion (see the module docstring).  ``frame_rate`` (Hz): the
    rate to sample at, default the animation's own (its keys' spacing).  ValueError naming the
    file and what is wrong: no skin, no animation of it, an animated scale."""
    f = _File(source)
    doc = f.document
    nodes = doc.get("nodes", [])
    skins = doc.get("skins", [])
    if not skins:
        raise ValueError(f"{f.name}: the file has no skin, so no skeleton to read (a glTF skeleton is a skin's joints)")
    joints = list(dict.fromkeys(skins[0]["joints"]))
    parent_of = {c: p for p, node in enumerate(nodes) for c in node.get("children", [])}
    joint_set = set(joints)
    roots = [j for j in joints if parent_of.get(j) not in joint_set]
    if len(roots) != 1:
        names = ", ".join(nodes[r].get("name", str(r)) for r in roots[:5])
        raise ValueError(f"{f.name}: the skin's joints hang from {len(roots)} roots ({names}); one root is needed")
    for j in joints:
        if j != roots[0] and parent_of.get(j) not in joint_set:
            raise ValueError(f"{f.name}: joint {nodes[j].get('name', j)} hangs from a node outside the skin")
    order = _depth_first(roots[0], nodes, joint_set)
    above = np.eye(4)
    walk = parent_of.get(roots[0])
    while walk is not None:
        above = _matrix(nodes[walk]) @ above
        walk = parent_of.get(walk)
    chosen = _animation(f, animation)
    times, rate, sampled = _sample(f, chosen, set(order), frame_rate)
    return _motion(f, nodes, order, parent_of, above, chosen, rate, len(times), sampled)


def animation_names(source: Source) -> list[str]:
    """The names of a glTF file's animations in order (an unnamed one by its index)."""
    return [str(a.get("name") or i) for i, a in enumerate(_File(source).document.get("animations", []))]


def _depth_first(root: int, nodes: list[dict[str, Any]], joints: set[int]) -> list[int]:
    order, stack = [], [root]
    while stack:
        n = stack.pop()
        order.append(n)
        stack.extend(c for c in reversed(nodes[n].get("children", [])) if c in joints)
    return order


def _animation(f: _File, animation: int | str | None) -> dict[str, Any]:
    found = f.document.get("animations", [])
    if not found:
        raise ValueError(f"{f.name}: the file has no animation")
    if animation is None:
        return found[0]
    if isinstance(animation, int) and not isinstance(animation, bool):
        if not 0 <= animation < len(found):
            raise ValueError(
                f"{f.name}: animation {animation} asked for; the file has {len(found)} (0 to {len(found) - 1})"
            )
        return found[animation]
    for a in found:
        if a.get("name") == animation:
            return a
    names = ", ".join(repr(a.get("name", "")) for a in found)
    raise ValueError(f"{f.name}: no animation named {animation!r}; it has {names}")


def _sample(
    f: _File, animation: dict[str, Any], joints: set[int], frame_rate: float | None
) -> tuple[np.ndarray, float, dict[tuple[int, str], np.ndarray]]:
    """The frame times, their rate and each (node, path) channel's values at them."""
    channels = []
    for channel in animation.get("channels", []):
        target = channel.get("target", {})
        if target.get("node") in joints and target.get("path") in ("rotation", "translation", "scale"):
            sampler = animation["samplers"][channel["sampler"]]
            keys = f.accessor(sampler["input"])[:, 0]
            values = f.accessor(sampler["output"])
            channels.append((target["node"], target["path"], keys, values, sampler.get("interpolation", "LINEAR")))
    if not channels:
        raise ValueError(f"{f.name}: animation {animation.get('name', '')!r} moves none of the skin's joints")
    extras = animation.get("extras", {}) if isinstance(animation.get("extras"), dict) else {}
    longest = max(channels, key=lambda c: len(c[2]))[2]
    start = min(c[2][0] for c in channels if len(c[2]))
    end = max(c[2][-1] for c in channels if len(c[2]))
    own = extras.get("frame_rate")
    if frame_rate is None:
        if isinstance(own, (int, float)) and own > 0:
            frame_rate = float(own)
        elif len(longest) > 1:
            frame_rate = 1.0 / float(np.median(np.diff(longest)))
        else:
            frame_rate = 30.0
    if not (np.isfinite(frame_rate) and frame_rate > 0):
        raise ValueError(f"{f.name}: the animation's keys give no frame rate; give one (frame_rate=, --frame-rate)")
    count = int(np.floor((end - start) * frame_rate + 1e-3)) + 1
    times = start + np.arange(count) / frame_rate
    sampled = {}
    for node, path, keys, values, interpolation in channels:
        sampled[(node, path)] = _at(keys, values, times, interpolation, path == "rotation")
    return times, frame_rate, sampled


def _at(keys: np.ndarray, values: np.ndarray, times: np.ndarray, interpolation: str, rotation: bool) -> np.ndarray:
    """A sampler's values at ``times``: its keys themselves where they are the frames (a file
    of ours), else interpolated as it says."""
    if interpolation == "CUBICSPLINE":
        tangents_in, points, tangents_out = values[0::3], values[1::3], values[2::3]
    else:
        points = values
    if len(keys) == len(times) and np.allclose(keys, times.astype(np.float32), rtol=0, atol=1e-6 * max(1.0, times[-1])):
        out = points.copy()
    else:
        i = np.clip(np.searchsorted(keys, times, side="right") - 1, 0, max(len(keys) - 2, 0))
        j = np.minimum(i + 1, len(keys) - 1)
        span = keys[j] - keys[i]
        u = np.clip(np.divide(times - keys[i], span, out=np.zeros_like(times), where=span > 0), 0.0, 1.0)
        if interpolation == "STEP" or len(keys) == 1:
            out = points[np.where(u >= 1.0, j, i)]
        elif interpolation == "CUBICSPLINE":
            u2, u3 = u * u, u * u * u
            d = span[:, None]
            out = (
                (2 * u3 - 3 * u2 + 1)[:, None] * points[i]
                + (u3 - 2 * u2 + u)[:, None] * d * tangents_out[i]
                + (-2 * u3 + 3 * u2)[:, None] * points[j]
                + (u3 - u2)[:, None] * d * tangents_in[j]
            )
        elif rotation:
            wxyz = [3, 0, 1, 2]
            out = slerp(points[i][:, wxyz], points[j][:, wxyz], u)[:, [1, 2, 3, 0]]
        else:
            out = points[i] + u[:, None] * (points[j] - points[i])
    if rotation:
        out = out / np.linalg.norm(out, axis=1, keepdims=True)
    return out


def _motion(f, nodes, order, parent_of, above, animation, rate, frames, sampled) -> Motion:
    index = {n: i for i, n in enumerate(order)}
    names = [str(nodes[n].get("name") or f"joint{n}") for n in order]
    if len(set(names)) != len(names):
        seen: dict[str, int] = {}
        for i, name in enumerate(names):
            seen[name] = seen.get(name, 0) + 1
            if seen[name] > 1:
                names[i] = f"{name}_{seen[name]}"
    rest = [_matrix(nodes[n]) for n in order]
    # the uniform scale each joint's children are measured in: the folded nodes' and the joints' above
    scale_above, rotation_above, offset_above = _split(above, f"{f.name}: the node above the skin's root")
    scales = np.empty(len(order))
    rotations = np.empty((len(order), frames, 4))
    translations = np.empty((len(order), frames, 3))
    for i, n in enumerate(order):
        s, r, t = _split(rest[i], f"{f.name}: joint {names[i]}")
        if (n, "scale") in sampled:
            animated_scale = sampled[(n, "scale")]
            if not np.allclose(animated_scale, animated_scale[:1], rtol=1e-5) or not np.allclose(
                animated_scale, animated_scale[0, 0], rtol=1e-5
            ):
                raise ValueError(f"{f.name}: joint {names[i]}'s scale is animated, which a BVH skeleton cannot hold")
            s = float(animated_scale[0, 0])
        scales[i] = s
        if (n, "rotation") in sampled:
            rotations[i] = sampled[(n, "rotation")][:, [3, 0, 1, 2]]
        else:
            rotations[i] = matrices_to_quaternions(r)
        translations[i] = sampled.get((n, "translation"), t)
    measure = np.empty(len(order))  # the scale a joint's translation is drawn in: its parents'
    for i, n in enumerate(order):
        measure[i] = scale_above if i == 0 else measure[index[parent_of[n]]] * scales[index[parent_of[n]]]
    translations *= measure[:, None, None]
    # the root: the nodes above turn and move it
    root_q = _quaternion_product(matrices_to_quaternions(rotation_above), rotations[0])
    rotations[0] = root_q
    translations[0] = translations[0] @ rotation_above.T + offset_above
    moving = {n for (n, path) in sampled if path == "translation"}
    angles = np.degrees(
        quaternions_to_euler(rotations.reshape(-1, 4), "zxy", extrinsic=False).reshape(len(order), frames, 3)
    )
    angles = unroll_euler(angles, "zxy", axis=1, degrees=True)
    bones, pairs, columns = [], [], [translations[0], angles[0]]
    for i, n in enumerate(order[1:], start=1):
        parent = names[index[parent_of[n]]]
        leaf = not any(c in index for c in nodes[n].get("children", []))
        still = (n, "rotation") not in sampled and n not in moving
        x, y, z = (float(v) for v in translations[i, 0])
        offset = (x, y, z)
        if leaf and still:
            bones.append(Bone(names[i], direction=offset, length=float(np.linalg.norm(offset)), end_site=True))
        else:
            dofs = (("tx", "ty", "tz") if n in moving else ()) + ORDER
            bones.append(Bone(names[i], direction=offset, length=float(np.linalg.norm(offset)), dofs=dofs))
            if n in moving:
                columns.append(translations[i])
            columns.append(angles[i])
        pairs.append((parent, (names[i],)))
    pairs = [("root" if p == names[0] else p, c) for p, c in pairs]
    skeleton = Skeleton(
        bones=tuple(bones),
        hierarchy=canonical_hierarchy(tuple(bones), pairs),
        root=Root(order=("tx", "ty", "tz", *ORDER), position=(0.0, 0.0, 0.0), name=names[0]),
        name=str(animation.get("name") or ""),
        units=(("length", "m"), ("angle", "deg")),  # glTF states metres
        convention="bvh",
    )
    extras = animation.get("extras", {}) if isinstance(animation.get("extras"), dict) else {}
    first = extras.get("first_frame", 1)
    values = np.concatenate([c.reshape(frames, -1) for c in columns], axis=1)
    return Motion(
        skeleton, values, frame_rate=float(rate), first_frame=int(first) if isinstance(first, int) else 1, header=()
    )


def _quaternion_product(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a b for one quaternion a and quaternions b (..., 4), (w, x, y, z)."""
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = np.moveaxis(b, -1, 0)
    return np.stack(
        [
            w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
            w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
            w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
        ],
        axis=-1,
    )
