"""USD out, judged by OpenUSD itself (usd-core): UsdSkel's skeleton query must put every joint where
our forward kinematics does (metres, turned upright and forward) at every time code, on every
real take and on variants of real takes laid out as other producers' rigs lay them out; the
stage states its units, axis and rate, and passes OpenUSD's own validators."""

import subprocess
import sys

import numpy as np
import pytest

import motiontheater as mt
from test_gltf import IDS, TOLERANCE, expected, written_cases

pxr = pytest.importorskip("pxr", reason="usd-core is not installed (pip install usd-core)")
from pxr import Usd, UsdGeom, UsdSkel, UsdValidation

from motiontheater.views.usd import identifiers, joint_paths, write_usd


def world_positions(stage):
    """{variant: (time codes, joints, 3)} joint world origins UsdSkel computes, per take."""
    root = UsdSkel.Root(stage.GetDefaultPrim())
    takes = root.GetPrim().GetVariantSets().GetVariantSet("take")
    out = {}
    for name in takes.GetVariantNames():
        takes.SetVariantSelection(name)
        cache = UsdSkel.Cache()
        cache.Populate(root, Usd.TraverseInstanceProxies())
        skeleton = UsdSkel.Skeleton(stage.GetPrimAtPath(root.GetPath().AppendChild("Skeleton")))
        query = cache.GetSkelQuery(skeleton)
        animation = query.GetAnimQuery()
        times = animation.GetJointTransformTimeSamples() or [stage.GetStartTimeCode()]
        frames = []
        for time in times:
            world = query.ComputeJointWorldTransforms(UsdGeom.XformCache(time))
            frames.append(np.array(world)[:, 3, :3])
        out[name] = (np.array(times), np.array(frames))
    return out


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """Each case's USD file, written once (see test_gltf.written_cases)."""
    return written_cases(tmp_path_factory.mktemp("usdc"), ".usdc", write_usd)


@pytest.mark.parametrize("case", IDS)
def test_usd_puts_every_joint_where_we_do(written, case):
    take, armature, points, path = written[case]
    stage = Usd.Stage.Open(str(path))
    assert UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.y and UsdGeom.GetStageMetersPerUnit(stage) == 1.0
    assert stage.GetTimeCodesPerSecond() == take.frame_rate
    skeleton = UsdSkel.Skeleton(stage.GetPrimAtPath("/Motion/Skeleton"))
    assert list(skeleton.GetJointNamesAttr().Get()) == list(armature.names)
    ((times, found),) = world_positions(stage).values()
    moving = len(armature.turning) or len(armature.moving)
    if moving:
        np.testing.assert_array_equal(times, take.first_frame + np.arange(take.frames))
    np.testing.assert_allclose(found, points[: len(found)], rtol=0, atol=TOLERANCE)


def test_text_and_binary_hold_the_same_stage(data_dir, tmp_path):
    take = mt.read_take(data_dir / "bvh" / "walk01.bvh")
    mt.export(take, tmp_path / "a.usda")
    mt.export(take, tmp_path / "a.usdc")
    assert (tmp_path / "a.usda").read_bytes().startswith(b"#usda 1.0")
    assert (tmp_path / "a.usdc").read_bytes().startswith(b"PXR-USDC")
    a, b = (world_positions(Usd.Stage.Open(str(tmp_path / n))) for n in ("a.usda", "a.usdc"))
    np.testing.assert_array_equal(a["walk01"][1], b["walk01"][1])


def test_several_takes_are_variants_of_one_skeleton(data_dir, tmp_path):
    takes = [mt.read_take(data_dir / "cmu" / n) for n in ("02_01.amc", "02_02.amc")]
    mt.export(takes, tmp_path / "both.usda")
    stage = Usd.Stage.Open(str(tmp_path / "both.usda"))
    selected = stage.GetDefaultPrim().GetVariantSets().GetVariantSet("take").GetVariantSelection()
    assert selected == "02_01"  # the first take, unless a user picks another
    found = world_positions(stage)
    assert list(found) == ["02_01", "02_02"]
    for take, (times, points) in zip(takes, found.values()):
        _, want = expected(take)
        assert len(times) == take.frames and times[0] == take.first_frame
        np.testing.assert_allclose(points, want, rtol=0, atol=TOLERANCE)


def test_the_body_is_skinned_and_passes_usds_validators(data_dir, tmp_path):
    take = mt.read_take(data_dir / "cmu" / "01_01.amc")
    target = tmp_path / "body.usdc"
    mt.export(take, target)
    stage = Usd.Stage.Open(str(target))
    validators = UsdValidation.ValidationRegistry().GetOrLoadAllValidators()
    errors = UsdValidation.ValidationContext(validators).Validate(stage)
    assert [(e.GetName(), e.GetMessage()) for e in errors] == []
    cache = UsdSkel.Cache()
    root = UsdSkel.Root(stage.GetDefaultPrim())
    cache.Populate(root, Usd.TraverseInstanceProxies())
    (binding,) = cache.ComputeSkelBindings(root, Usd.TraverseInstanceProxies())
    (skinning,) = binding.GetSkinningTargets()
    assert skinning.GetPrim().GetPath() == "/Motion/Body" and skinning.HasJointInfluences()
    mt.export(take, tmp_path / "bare.usda", mesh=False)
    assert not Usd.Stage.Open(str(tmp_path / "bare.usda")).GetPrimAtPath("/Motion/Body")


def test_takes_at_two_rates_are_refused(data_dir, tmp_path):
    take = mt.read_take(data_dir / "cmu" / "02_01.amc")
    with pytest.raises(ValueError, match="share its time codes; give them one rate"):
        mt.export([take, take.resample(rate=60.0)], tmp_path / "two.usda")
    mt.export([take, take.resample(rate=60.0)], tmp_path / "two.usda", rate=30.0)
    assert Usd.Stage.Open(str(tmp_path / "two.usda")).GetTimeCodesPerSecond() == 30.0


def test_names_usd_forbids_become_identifiers_and_are_kept(data_dir):
    assert identifiers(["mixamorig:Hips", "02_01", "a b", "a_b"]) == ["mixamorig_Hips", "_2_01", "a_b", "a_b_2"]
    assert identifiers(["02_01", "my take (2)", "a-b"], variants=True) == ["02_01", "my_take__2_", "a-b"]
    armature, _ = expected(mt.read_take(data_dir / "cmu" / "01_01.amc"))
    paths = joint_paths(armature)
    assert paths[0] == "root" and all(p.startswith("root/") for p in paths[1:])
    assert len(set(paths)) == armature.nodes


def test_export_to_usd_on_the_command_line(copies):
    folder = copies("cmu", ["02.asf", "02_01.amc"])
    done = subprocess.run(
        [sys.executable, "-m", "motiontheater", "export", "02_01.amc", "-o", "out/02_01.usdc"],
        capture_output=True,
        text=True,
        cwd=folder,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    assert "wrote" in done.stdout and (folder / "out" / "02_01.usdc").exists()
