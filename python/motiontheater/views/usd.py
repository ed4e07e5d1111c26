"""USD out (``.usda`` text, ``.usdc`` binary) through OpenUSD's own library (``usd-core``, the
``usd`` extra): a SkelRoot holding a Skeleton with the armature's rest and bind transforms, a
SkelAnimation per take, and optionally the capsule body skinned to it.

The stage states its units (``metersPerUnit`` 1: the armature is in metres) and axis (+Y up), and
its time codes are the take's frame numbers at ``timeCodesPerSecond`` = the take's rate, so that
time code 1 of a CMU take is its frame 1.  Several takes are several SkelAnimations, chosen by the
SkelRoot's variant set ``take`` (the first selected), since a skeleton binds one animation at a
time.  USD joint paths must be identifiers; the joints' names as the file spells them are kept in
the Skeleton's ``jointNames``.
"""

from __future__ import annotations

import os
import re
import tempfile
from collections.abc import Sequence

import numpy as np

from mtcore.rotations import quaternions_to_matrices

from .._io import Source, output
from ..model.motion import Motion
from .armature import Armature, Track, animated
from .capsules import capsules


def _require_usd() -> None:
    try:
        import pxr.UsdSkel  # noqa: F401
    except ImportError:
        raise ValueError("writing USD needs OpenUSD's library: pip install 'motiontheater[usd]' (usd-core)") from None


def identifiers(names: Sequence[str], *, variants: bool = False) -> list[str]:
    """The names made USD identifiers (``mixamorig:Hips`` -> ``mixamorig_Hips``), or variant
    names (which may also start with a digit and hold ``-`` and ``|``), unique."""
    from pxr import Tf

    taken: set[str] = set()
    out: list[str] = []
    for name in names:
        base = re.sub(r"[^\w|-]", "_", name, flags=re.ASCII) if variants else Tf.MakeValidIdentifier(name)
        found, n = base, 2
        while found in taken:
            found, n = f"{base}_{n}", n + 1
        taken.add(found)
        out.append(found)
    return out


def joint_paths(armature: Armature) -> list[str]:
    """Each node's joint path for UsdSkel (``Hips/Spine/...``): its name as an identifier under
    its parent's."""
    paths: list[str] = []
    for element, parent in zip(identifiers(armature.names), armature.parents.tolist()):
        paths.append(element if parent < 0 else f"{paths[parent]}/{element}")
    return paths


def _matrices(Vt, matrices: np.ndarray):
    """Column-vector 4 x 4 matrices as USD's, which act on row vectors."""
    return Vt.Matrix4dArray.FromNumpy(np.ascontiguousarray(matrices.transpose(0, 2, 1)))


def _animation(stage, path: str, armature: Armature, track: Track, joints: list[str]):
    """The take's SkelAnimation: every node's local rotation and translation at each time code,
    the nodes a take does not animate at their rest transform."""
    from pxr import UsdSkel, Vt

    animation = UsdSkel.Animation.Define(stage, path)
    animation.CreateJointsAttr(joints)
    animation.CreateScalesAttr(Vt.Vec3hArray.FromNumpy(np.ones((armature.nodes, 3), np.float16)))
    rotations = np.tile(armature.rotations.astype(np.float32), (track.frames, 1, 1))
    rotations[:, armature.turning] = track.rotations.transpose(1, 0, 2)
    translations = np.tile(armature.translations.astype(np.float32), (track.frames, 1, 1))
    translations[:, armature.moving] = track.translations.transpose(1, 0, 2)
    rotate, move = animation.CreateRotationsAttr(), animation.CreateTranslationsAttr()
    if not len(armature.moving):
        move.Set(Vt.Vec3fArray.FromNumpy(translations[0]))
    for frame in range(track.frames):  # one array per time code: the library's interface
        time = track.first_frame + frame
        rotate.Set(Vt.QuatfArray.FromNumpy(rotations[frame]), time)
        if len(armature.moving):
            move.Set(Vt.Vec3fArray.FromNumpy(translations[frame]), time)
    return animation


def _body(stage, path: str, armature: Armature, skeleton) -> None:
    from pxr import UsdGeom, UsdSkel, Vt

    body = capsules(armature)
    mesh = UsdGeom.Mesh.Define(stage, path)
    mesh.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(body.positions))
    mesh.CreateNormalsAttr(Vt.Vec3fArray.FromNumpy(body.normals))
    mesh.SetNormalsInterpolation(UsdGeom.Tokens.vertex)
    mesh.CreateFaceVertexCountsAttr(Vt.IntArray.FromNumpy(np.full(len(body.triangles), 3, np.int32)))
    mesh.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(body.triangles.reshape(-1).astype(np.int32)))
    mesh.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)
    mesh.CreateDisplayColorAttr([(0.8, 0.75, 0.7)])
    binding = UsdSkel.BindingAPI.Apply(mesh.GetPrim())
    binding.CreateSkeletonRel().SetTargets([skeleton.GetPath()])
    binding.CreateJointIndicesPrimvar(False, 1).Set(Vt.IntArray.FromNumpy(body.nodes.astype(np.int32)))
    binding.CreateJointWeightsPrimvar(False, 1).Set(Vt.FloatArray.FromNumpy(np.ones(len(body.nodes), np.float32)))


def usd_stage(motions: Motion | Sequence[Motion], *, body: bool = True, names: Sequence[str] | None = None):
    """An in-memory stage of the takes (see :func:`write_usd`)."""
    _require_usd()
    from pxr import Sdf, Usd, UsdGeom, UsdSkel, Vt

    armature, tracks = animated(motions, names)
    stage = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    rate = tracks[0].frame_rate
    for track in tracks[1:]:
        if track.frame_rate != rate:
            raise ValueError(
                f"{track.name} runs at {track.frame_rate:g} Hz and {tracks[0].name} at {rate:g} Hz: the takes "
                "of a USD file share its time codes; give them one rate (rate=..., --rate)"
            )
    stage.SetTimeCodesPerSecond(rate)
    stage.SetFramesPerSecond(rate)
    stage.SetStartTimeCode(min(t.first_frame for t in tracks))
    stage.SetEndTimeCode(max(t.first_frame + max(t.frames - 1, 0) for t in tracks))
    root = UsdSkel.Root.Define(stage, "/Motion")
    stage.SetDefaultPrim(root.GetPrim())
    skeleton = UsdSkel.Skeleton.Define(stage, "/Motion/Skeleton")
    joints = joint_paths(armature)
    skeleton.CreateJointsAttr(joints)
    skeleton.CreateJointNamesAttr(list(armature.names))
    local = np.zeros((armature.nodes, 4, 4))
    local[:, :3, :3] = quaternions_to_matrices(armature.rotations[:, [3, 0, 1, 2]])
    local[:, :3, 3] = armature.translations
    local[:, 3, 3] = 1.0
    skeleton.CreateRestTransformsAttr(_matrices(Vt, local))
    skeleton.CreateBindTransformsAttr(_matrices(Vt, armature.rest_world))
    binding = UsdSkel.BindingAPI.Apply(skeleton.GetPrim())
    source = binding.CreateAnimationSourceRel()
    named = [track.name for track in tracks]
    paths = [f"/Motion/Animations/{name}" for name in identifiers(named)]
    UsdGeom.Scope.Define(stage, "/Motion/Animations")
    takes_set = root.GetPrim().GetVariantSets().AddVariantSet("take")
    variants = identifiers(named, variants=True)
    for path, track, variant in zip(paths, tracks, variants):
        _animation(stage, path, armature, track, joints)
        takes_set.AddVariant(variant)
        takes_set.SetVariantSelection(variant)
        with takes_set.GetVariantEditContext():
            source.SetTargets([Sdf.Path(path)])
    takes_set.SetVariantSelection(variants[0])
    if body:
        _body(stage, "/Motion/Body", armature, skeleton)
    root.GetPrim().SetCustomDataByKey("up", armature.up)
    root.GetPrim().SetCustomDataByKey("forward", armature.forward)
    return stage


def write_usd(
    motions: Motion | Sequence[Motion],
    target: Source,
    *,
    body: bool = True,
    binary: bool | None = None,
    names: Sequence[str] | None = None,
) -> None:
    """Write takes of one skeleton as USD (UsdSkel), a SkelAnimation per take (named ``names``,
    default after their files): text (``.usda``) where ``binary`` is false or the target ends
    in ``.usda``, else OpenUSD's binary crate (``.usdc``, ``.usd``).  ``body``: a capsule along
    each bone, skinned.  A path is written atomically.  ValueError for takes of different
    skeletons, NaN or inf values, a skeleton of one joint, or where usd-core is not installed."""
    if binary is None:
        binary = not isinstance(target, (str, os.PathLike)) or not os.fspath(target).lower().endswith(".usda")
    stage = usd_stage(motions, body=body, names=names)
    with tempfile.TemporaryDirectory() as folder:
        scratch = os.path.join(folder, "stage.usdc" if binary else "stage.usda")
        if not stage.GetRootLayer().Export(scratch):
            raise ValueError("OpenUSD could not write the stage")
        with open(scratch, "rb") as f, output(target) as out:
            while chunk := f.read(1 << 20):
                out.write(chunk)
