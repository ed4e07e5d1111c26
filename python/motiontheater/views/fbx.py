"""FBX out (binary, version 7400): a LimbNode model per joint with its rest transform and a bind
pose, optionally a body of capsules skinned to it (a Skin deformer, a Cluster per node), and an
animation stack per take, its curves keyed at every frame with linear interpolation.

The file says +Y up, +Z front, +X the third axis (GlobalSettings), and its unit is the
centimetre with UnitScaleFactor 1: FBX's own unit, the one MotionBuilder, Maya and Mixamo write,
so that a reader that ignores UnitScaleFactor (three.js's FBXLoader) still gets the figure at the
size FBX tools assume by default.  Rotations are Euler angles in degrees, RotationOrder eEulerXYZ
(R = Rz Ry Rx), each node's keys unrolled so that consecutive keys never jump a whole turn.
Arrays are written uncompressed: three.js's FBXLoader inflates compressed ones only with a
library of its own loaded beside it.  The records' layout follows Blender's reader and writer
(``io_scene_fbx/parse_fbx.py``, ``encode_bin.py``) and the FBX SDK's files they mirror.
"""

from __future__ import annotations

import itertools
import struct
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from mtcore.rotations import quaternions_to_euler, unroll_euler

from .._io import Source, output
from .._version import __version__
from ..model.motion import Motion
from .armature import Armature, Track, animated
from .capsules import capsules
from .gltf import node_names

VERSION = 7400
MAGIC = b"Kaydara FBX Binary  \x00\x1a\x00"
# The footer's fixed bytes, as the FBX SDK writes them (and Blender's encode_bin.py after it)
FOOTER_ID = b"\xfa\xbc\xab\x09\xd0\xc8\xd4\x66\xb1\x76\xfb\x83\x1c\xf7\x26\x7e"
FOOTER_MAGIC = b"\xf8\x5a\x8c\x6a\xde\xf5\xd9\x7e\xec\xe9\x0c\xe3\x75\x8f\x29\x0b"
NULL_RECORD = bytes(13)  # ends a list of nested records (three uint32 and a name length, all 0)
# Records the SDK ends with a null record even with nothing nested (Blender's encode_bin.py found so)
ALWAYS_NESTED = {"AnimationStack", "AnimationLayer"}
KTIME = 46186158000  # FBX time ticks per second
CM = 100.0  # centimetres per metre: the file's unit (see the module docstring)
# TimeMode enums of the FBX SDK's standard rates; any other is eCustom (14) with CustomFrameRate
TIME_MODES = {120.0: 1, 100.0: 2, 60.0: 3, 50.0: 4, 48.0: 5, 30.0: 6, 25.0: 10, 24.0: 11, 96.0: 15, 72.0: 16}
CUSTOM_RATE = 14
# Each key linear (0x4), with the tangent bits and data Blender's exporter writes beside it (auto,
# time-independent, clamp-progressive; they do not change a linear key)
KEY_FLAGS = 0x4 | 0x100 | 0x2000 | 0x4000
KEY_DATA = (0.0, 0.0, 9.419963346924634e-30, 0.0)


class Long(int):
    """An integer written as FBX's int64 ('L'): object ids and times; a plain int is an int32."""


@dataclass
class Record:
    """An FBX node record: a name, its properties (Python values, see :func:`_encode`) and
    nested records."""

    name: str
    properties: tuple[Any, ...] = ()
    children: list[Record] = field(default_factory=list)

    def add(self, name: str, *properties: Any) -> Record:
        """A new nested record, returned."""
        record = Record(name, properties)
        self.children.append(record)
        return record


def _encode(value: Any) -> bytes:
    """One property: its type code and data, little-endian; arrays by their dtype, uncompressed."""
    if isinstance(value, bool):
        return b"C" + struct.pack("<?", value)
    if isinstance(value, Long):
        return b"L" + struct.pack("<q", value)
    if isinstance(value, int):
        return b"I" + struct.pack("<i", value)
    if isinstance(value, float):
        return b"D" + struct.pack("<d", value)
    if isinstance(value, str):
        value = value.encode("utf-8")
    if isinstance(value, bytes):
        return b"S" + struct.pack("<I", len(value)) + value
    array = np.ascontiguousarray(value)
    code = {np.dtype("<f4"): b"f", np.dtype("<f8"): b"d", np.dtype("<i4"): b"i", np.dtype("<i8"): b"l"}[array.dtype]
    return code + struct.pack("<III", array.size, 0, array.nbytes) + array.tobytes()


def _serialise(record: Record, offset: int) -> list[bytes]:
    """The bytes of ``record`` starting at ``offset`` in the file (its end offset is absolute).
    Nested records end with the null record; so does a record without properties, as the SDK
    writes them (Blender's encode_bin.py too)."""
    properties = b"".join(_encode(p) for p in record.properties)
    name = record.name.encode("ascii")
    parts: list[bytes] = []
    at = offset + 13 + len(name) + len(properties)
    for child in record.children:
        for part in _serialise(child, at):
            parts.append(part)
            at += len(part)
    if record.children or not record.properties or record.name in ALWAYS_NESTED:
        parts.append(NULL_RECORD)
        at += len(NULL_RECORD)
    head = struct.pack("<IIIB", at, len(record.properties), len(properties), len(name)) + name + properties
    return [head, *parts]


def _name(name: str, kind: str) -> bytes:
    """An object's name as FBX stores it: the name, 0x00 0x01, its class."""
    return name.encode("utf-8") + b"\x00\x01" + kind.encode("ascii")


def _p(parent: Record, name: str, kind: str, label: str, flags: str, *values: Any) -> None:
    """A property of a Properties70 block."""
    parent.add("P", name, kind, label, flags, *values)


def _matrix(m: np.ndarray) -> np.ndarray:
    """A 4 x 4 (column vectors, translation last column, metres) as FBX stores it: column by
    column, in centimetres."""
    m = m.copy()
    m[:3, 3] *= CM
    return m.T.reshape(16).astype(np.float64)


def _euler(quaternions: np.ndarray) -> np.ndarray:
    """eEulerXYZ degrees (..., 3) of quaternions (..., 4) x, y, z, w."""
    return quaternions_to_euler(np.asarray(quaternions)[..., [3, 0, 1, 2]], "xyz", extrinsic=True, degrees=True)


class _Scene:
    """The Objects and Connections records, filled object by object, and each kind's count
    (for Definitions)."""

    def __init__(self) -> None:
        self.objects = Record("Objects")
        self.connections = Record("Connections")
        self.counts: dict[str, int] = {}
        self._ids = itertools.count(1)  # 0 is the scene's root

    def new_id(self) -> Long:
        """An id no other object has."""
        return Long(next(self._ids))

    def object(self, kind: str, name: str, cls: str, subclass: str) -> tuple[Record, Long]:
        """A new object record and its id."""
        uid = self.new_id()
        self.counts[kind] = self.counts.get(kind, 0) + 1
        return self.objects.add(kind, uid, _name(name, cls), subclass), uid

    def connect(self, child: int, parent: int, prop: str | None = None) -> None:
        """child -> parent (an object's property where ``prop``)."""
        if prop is None:
            self.connections.add("C", "OO", Long(child), Long(parent))
        else:
            self.connections.add("C", "OP", Long(child), Long(parent), prop)


def _skeleton(scene: _Scene, armature: Armature) -> list[Long]:
    """A LimbNode model (with its node attribute) per node at its rest transform, each under its
    parent; the models' ids."""
    rotations = _euler(armature.rotations)
    models: list[Long] = []
    for n, name in enumerate(node_names(armature)):
        attribute, attribute_id = scene.object("NodeAttribute", name, "NodeAttribute", "LimbNode")
        attribute.add("TypeFlags", "Skeleton")
        _p(attribute.add("Properties70"), "Size", "double", "Number", "", 1.0)
        model, uid = scene.object("Model", name, "Model", "LimbNode")
        model.add("Version", 232)
        props = model.add("Properties70")
        _p(props, "RotationOrder", "enum", "", "", 0)
        _p(props, "InheritType", "enum", "", "", 1)
        _p(props, "DefaultAttributeIndex", "int", "Integer", "", 0)
        _p(props, "Lcl Translation", "Lcl Translation", "", "A", *(CM * armature.translations[n]).tolist())
        _p(props, "Lcl Rotation", "Lcl Rotation", "", "A", *rotations[n].tolist())
        _p(props, "Lcl Scaling", "Lcl Scaling", "", "A", 1.0, 1.0, 1.0)
        model.add("Shading", True)
        model.add("Culling", "CullingOff")
        scene.connect(attribute_id, uid)
        scene.connect(uid, models[armature.parents[n]] if n else 0)
        models.append(uid)
    return models


def _body(scene: _Scene, armature: Armature, models: list[Long]) -> Long:
    """The capsule mesh as a Mesh model skinned by a Cluster per node; the model's id."""
    body = capsules(armature)
    geometry, geometry_id = scene.object("Geometry", "body", "Geometry", "Mesh")
    geometry.add("GeometryVersion", 124)
    geometry.add("Vertices", (CM * body.positions.astype(np.float64)).reshape(-1))
    corners = body.triangles.astype(np.int32)
    corners[:, 2] = ~corners[:, 2]  # a polygon's last corner is stored as -(index + 1)
    geometry.add("PolygonVertexIndex", corners.reshape(-1))
    normals = geometry.add("LayerElementNormal", 0)
    normals.add("Version", 101)
    normals.add("Name", "")
    normals.add("MappingInformationType", "ByVertice")
    normals.add("ReferenceInformationType", "Direct")
    normals.add("Normals", body.normals.astype(np.float64).reshape(-1))
    layer = geometry.add("Layer", 0)
    layer.add("Version", 100)
    element = layer.add("LayerElement")
    element.add("Type", "LayerElementNormal")
    element.add("TypedIndex", 0)
    model, model_id = scene.object("Model", "body", "Model", "Mesh")
    model.add("Version", 232)
    props = model.add("Properties70")
    _p(props, "DefaultAttributeIndex", "int", "Integer", "", 0)
    _p(props, "InheritType", "enum", "", "", 1)
    model.add("Shading", True)
    model.add("Culling", "CullingOff")
    scene.connect(geometry_id, model_id)
    scene.connect(model_id, 0)
    skin, skin_id = scene.object("Deformer", armature.skeleton.name or "skeleton", "Deformer", "Skin")
    skin.add("Version", 101)
    skin.add("Link_DeformAcuracy", 50.0)
    scene.connect(skin_id, geometry_id)
    for n, name in enumerate(node_names(armature)):
        cluster, cluster_id = scene.object("Deformer", name, "SubDeformer", "Cluster")
        cluster.add("Version", 100)
        cluster.add("UserData", "", "")
        vertices = np.flatnonzero(body.nodes == n).astype(np.int32)
        if len(vertices):
            cluster.add("Indexes", vertices)
            cluster.add("Weights", np.ones(len(vertices)))
        # Transform: the mesh's world (the identity) in the bone's bind frame; TransformLink: the bone's
        cluster.add("Transform", _matrix(armature.inverse_bind[n]))
        cluster.add("TransformLink", _matrix(armature.rest_world[n]))
        scene.connect(cluster_id, skin_id)
        scene.connect(models[n], cluster_id)
    return model_id


def _bind_pose(scene: _Scene, armature: Armature, models: list[Long], body: Long | None) -> None:
    pose, _ = scene.object("Pose", armature.skeleton.name or "skeleton", "Pose", "BindPose")
    pose.add("Type", "BindPose")
    pose.add("Version", 100)
    nodes = list(zip(models, armature.rest_world))
    if body is not None:
        nodes.insert(0, (body, np.eye(4)))
    pose.add("NbPoseNodes", len(nodes))
    for uid, world in nodes:
        node = pose.add("PoseNode")
        node.add("Node", uid)
        node.add("Matrix", _matrix(world))


def key_times(track: Track) -> np.ndarray:
    """(frames,) int64 FBX ticks of a track's frames, the first at 0."""
    return np.rint(np.arange(track.frames) * (KTIME / track.frame_rate)).astype(np.int64)


def _animation(scene: _Scene, armature: Armature, track: Track, models: list[Long]) -> None:
    """An AnimationStack with one AnimationLayer; an "R" curve node (d|X, d|Y, d|Z) per turning
    node and a "T" one per moving node, each curve keyed at every frame."""
    times = key_times(track)
    stack, stack_id = scene.object("AnimationStack", track.name, "AnimStack", "")
    props = stack.add("Properties70")
    for start in ("LocalStart", "ReferenceStart"):
        _p(props, start, "KTime", "Time", "", Long(0))
        _p(props, start.replace("Start", "Stop"), "KTime", "Time", "", Long(times[-1]))
    _, layer_id = scene.object("AnimationLayer", track.name, "AnimLayer", "")
    scene.connect(layer_id, stack_id)
    degrees = unroll_euler(_euler(track.rotations), "xyz", axis=1, degrees=True)
    for attribute, prop, nodes, values in (
        ("R", "Lcl Rotation", armature.turning, degrees),
        ("T", "Lcl Translation", armature.moving, CM * track.translations.astype(np.float64)),
    ):
        for node, series in zip(nodes.tolist(), values):
            series = series.astype(np.float32)
            curve_node, curve_node_id = scene.object("AnimationCurveNode", attribute, "AnimCurveNode", "")
            props = curve_node.add("Properties70")
            for axis in range(3):
                _p(props, f"d|{'XYZ'[axis]}", "Number", "", "A", float(series[0, axis]))
            scene.connect(curve_node_id, layer_id)
            scene.connect(curve_node_id, models[node], prop)
            for axis in range(3):
                curve, curve_id = scene.object("AnimationCurve", "", "AnimCurve", "")
                curve.add("Default", float(series[0, axis]))
                curve.add("KeyVer", 4008)
                curve.add("KeyTime", times)
                curve.add("KeyValueFloat", np.ascontiguousarray(series[:, axis]))
                curve.add("KeyAttrFlags", np.array([KEY_FLAGS], np.int32))
                curve.add("KeyAttrDataFloat", np.array(KEY_DATA, np.float32))
                curve.add("KeyAttrRefCount", np.array([len(times)], np.int32))
                scene.connect(curve_id, curve_node_id, f"d|{'XYZ'[axis]}")


def _header(scene: _Scene, first: Track) -> list[Record]:
    """FBXHeaderExtension, GlobalSettings, Documents and References."""
    header = Record("FBXHeaderExtension")
    header.add("FBXHeaderVersion", 1003)
    header.add("FBXVersion", VERSION)
    header.add("EncryptionType", 0)
    header.add("Creator", f"motiontheater {__version__}")
    settings = Record("GlobalSettings")
    settings.add("Version", 1000)
    props = settings.add("Properties70")
    for name, value in (("UpAxis", 1), ("FrontAxis", 2), ("CoordAxis", 0), ("OriginalUpAxis", 1)):
        _p(props, name, "int", "Integer", "", value)
        _p(props, f"{name}Sign", "int", "Integer", "", 1)
    _p(props, "UnitScaleFactor", "double", "Number", "", CM / 100.0)  # centimetres per file unit
    _p(props, "OriginalUnitScaleFactor", "double", "Number", "", CM / 100.0)
    _p(props, "TimeMode", "enum", "", "", TIME_MODES.get(first.frame_rate, CUSTOM_RATE))
    _p(props, "TimeSpanStart", "KTime", "Time", "", Long(0))
    _p(props, "TimeSpanStop", "KTime", "Time", "", Long(key_times(first)[-1]))
    _p(props, "CustomFrameRate", "double", "Number", "", float(first.frame_rate))
    documents = Record("Documents")
    documents.add("Count", 1)
    doc = documents.add("Document", scene.new_id(), "Scene", "Scene")
    doc_props = doc.add("Properties70")
    _p(doc_props, "SourceObject", "object", "", "")
    _p(doc_props, "ActiveAnimStackName", "KString", "", "", first.name)
    doc.add("RootNode", Long(0))
    return [header, Record("Creator", (f"motiontheater {__version__}",)), settings, documents, Record("References")]


def fbx_records(
    motions: Motion | Sequence[Motion], *, body: bool = True, names: Sequence[str] | None = None
) -> list[Record]:
    """The top-level records of the takes' file (see :func:`write_fbx`)."""
    armature, tracks = animated(motions, names)
    scene = _Scene()
    models = _skeleton(scene, armature)
    mesh = _body(scene, armature, models) if body else None
    _bind_pose(scene, armature, models, mesh)
    for track in tracks:
        _animation(scene, armature, track, models)
    definitions = Record("Definitions")
    definitions.add("Version", 100)
    definitions.add("Count", sum(scene.counts.values()) + 1)
    definitions.add("ObjectType", "GlobalSettings").add("Count", 1)
    for kind, count in scene.counts.items():
        definitions.add("ObjectType", kind).add("Count", count)
    takes_record = Record("Takes")
    takes_record.add("Current", tracks[0].name)
    for track in tracks:
        take = takes_record.add("Take", track.name)
        take.add("FileName", f"{track.name}.tak")
        stop = Long(key_times(track)[-1])
        take.add("LocalTime", Long(0), stop)
        take.add("ReferenceTime", Long(0), stop)
    return [*_header(scene, tracks[0]), definitions, scene.objects, scene.connections, takes_record]


def write_fbx(
    motions: Motion | Sequence[Motion],
    target: Source,
    *,
    body: bool = True,
    names: Sequence[str] | None = None,
) -> None:
    """Write takes of one skeleton as binary FBX 7400, an animation stack per take (named
    ``names``, default after their files), centimetres, +Y up, +Z front; the scene's frame rate
    is the first take's.  ``body``: a capsule along each bone, skinned, so that viewers draw a
    figure.  A path is written atomically.  ValueError for takes of different skeletons, NaN or
    inf values, a skeleton of one joint or a name that is not text."""
    records = fbx_records(motions, body=body, names=names)
    with output(target) as f:
        f.write(MAGIC + struct.pack("<I", VERSION))
        at = len(MAGIC) + 4
        for record in records:
            for part in _serialise(record, at):
                f.write(part)
                at += len(part)
        f.write(NULL_RECORD)
        at += len(NULL_RECORD)
        # The footer: its id, padding to a multiple of 16 (a whole 16 where already there), the
        # version, 120 zeros and the magic, as the SDK writes it
        pad = -(at + len(FOOTER_ID) + 4) % 16 or 16
        f.write(FOOTER_ID + bytes(4) + bytes(pad) + struct.pack("<I", VERSION) + bytes(120) + FOOTER_MAGIC)
