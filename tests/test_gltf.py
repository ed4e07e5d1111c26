"""glTF/GLB out and back, judged by its readers: pygltflib and the specification's rules, our own
reader, three.js's GLTFLoader in headless Chromium and Blender's importer.  Each must put every
joint where our forward kinematics does (metres, turned upright and forward) at every frame, on
every real take and on variants of real takes laid out as other producers' rigs lay them out."""

import json
import struct
import subprocess
import sys

import numpy as np
import pytest

import motiontheater as mt
from consumers import blender_positions, needs_blender, needs_three, three_page, three_positions  # noqa: F401
from corpus import real_files
from motiontheater.formats.gltf_read import read_gltf
from motiontheater.views.armature import animated
from motiontheater.views.gltf import node_names, write_gltf
from variants import with_offset_channels, with_static_root

TOLERANCE = 1e-5  # metres: 0.01 mm
TAKES = [p for p in real_files("*/*.amc") + real_files("*/*.bvh")]
VARIANT_TAKES = [p for p in TAKES if p.name in ("walk01.bvh", "16_15.bvh", "BvhToDeepMimic_0005_Walking001.bvh")]
VARIANTS = {
    "game rig": lambda take: with_static_root(with_offset_channels(take), shift=(250.0, 0.0, -400.0)),
    "z-up": lambda take: with_static_root(take, turn=(90.0, 0.0, 0.0), keep_world=False),
    "in mm": lambda take: take.with_units(length_factor=1000 * take.skeleton.meters_per_unit, length="mm"),
}
CASES = [(p, None) for p in TAKES] + [(p, v) for p in VARIANT_TAKES for v in VARIANTS]
IDS = [f"{p.parent.name}/{p.name}" + (f"-{v}" if v else "") for p, v in CASES]


def take_of(path, variant):
    take = mt.read_take(path)
    return take if variant is None else VARIANTS[variant](take)


def expected(take):
    """Every node's world origin per frame (frames, nodes, 3), metres, as the file must draw it."""
    armature, _ = animated(take)
    return armature, armature.scale * take.positions()[:, armature.origins] @ armature.turn.T


def written_cases(folder, suffix, write):
    """{case: (take, its armature, the positions it must give, its file)}, each file written by
    ``write(take, path)`` into ``folder``, named after the case with ``suffix``."""
    out = {}
    for (path, variant), name in zip(CASES, IDS):
        take = take_of(path, variant)
        armature, points = expected(take)
        target = folder / (name.replace("/", "_").replace(" ", "_") + suffix)
        write(take, target)
        out[name] = (take, armature, points, target)
    return out


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """Each case's GLB, written once (see written_cases)."""
    return written_cases(tmp_path_factory.mktemp("glb"), ".glb", write_gltf)


def key_times(take):
    """The animation's key times as the file holds them (float32 seconds)."""
    return (np.arange(take.frames) / take.frame_rate).astype(np.float32).astype(float)


def glb_document(path):
    data = path.read_bytes()
    magic, version, total = struct.unpack_from("<III", data)
    assert (magic, version, total) == (0x46546C67, 2, len(data))
    length, kind = struct.unpack_from("<II", data, 12)
    assert kind == 0x4E4F534A and length % 4 == 0
    document = json.loads(data[20 : 20 + length])
    binary_length, binary_kind = struct.unpack_from("<II", data, 20 + length)
    assert binary_kind == 0x004E4942 and binary_length % 4 == 0
    return document, data[28 + length : 28 + length + binary_length]


@pytest.mark.parametrize("case", IDS)
def test_the_file_keeps_the_specifications_rules(written, case):
    pygltflib = pytest.importorskip("pygltflib", reason="pygltflib is not installed (pip install pygltflib)")
    take, armature, _, path = written[case]
    loaded = pygltflib.GLTF2().load(str(path))
    assert len(loaded.nodes) == armature.nodes + 1 and len(loaded.animations) == 1
    assert loaded.skins[0].joints == list(range(armature.nodes))
    document, binary = glb_document(path)
    assert document["buffers"][0]["byteLength"] == len(binary)
    for view in document["bufferViews"]:
        assert view["byteOffset"] % 4 == 0 and view["byteOffset"] + view["byteLength"] <= len(binary)
    accessors = document["accessors"]

    def values(index):
        a = accessors[index]
        view = document["bufferViews"][a["bufferView"]]
        dtype = {5126: np.float32, 5123: np.uint16, 5125: np.uint32}[a["componentType"]]
        width = {"SCALAR": 1, "VEC3": 3, "VEC4": 4, "MAT4": 16}[a["type"]]
        flat = np.frombuffer(binary, dtype, a["count"] * width, view["byteOffset"])
        assert view["byteLength"] == flat.nbytes
        return flat.reshape(a["count"], width)

    primitive = document["meshes"][0]["primitives"][0]
    animation = document["animations"][0]
    bounded = [primitive["attributes"]["POSITION"]] + [s["input"] for s in animation["samplers"]]
    for index in bounded:  # min and max: required, and exactly the data's
        v = values(index)
        assert accessors[index]["min"] == v.min(axis=0).tolist() and accessors[index]["max"] == v.max(axis=0).tolist()
    times = values(animation["samplers"][0]["input"])[:, 0]
    assert len(times) == take.frames and (np.diff(times) > 0).all() and times[0] == 0
    for sampler, channel in zip(animation["samplers"], animation["channels"]):
        out = values(sampler["output"])
        assert len(out) == take.frames
        if channel["target"]["path"] == "rotation":
            np.testing.assert_allclose(np.linalg.norm(out, axis=1), 1.0, atol=1e-6)
            assert (np.einsum("ij,ij->i", out[1:], out[:-1]) >= 0).all()  # keys on one hemisphere
    weights = values(primitive["attributes"]["WEIGHTS_0"])
    np.testing.assert_array_equal(weights.sum(axis=1), 1.0)
    assert values(primitive["attributes"]["JOINTS_0"]).max() < armature.nodes
    inverse_bind = values(document["skins"][0]["inverseBindMatrices"]).reshape(-1, 4, 4).transpose(0, 2, 1)
    np.testing.assert_allclose(
        inverse_bind @ armature.rest_world, np.tile(np.eye(4), (armature.nodes, 1, 1)), atol=1e-5
    )
    assert animation["extras"] == {"frame_rate": take.frame_rate, "first_frame": take.first_frame}


@pytest.mark.parametrize("case", IDS)
def test_our_reader_gives_the_take_back(written, case):
    take, armature, points, path = written[case]
    back = read_gltf(path)
    assert (back.frames, back.frame_rate, back.first_frame) == (take.frames, take.frame_rate, take.first_frame)
    index = [back.skeleton.point_names.index(n) for n in node_names(armature)]
    np.testing.assert_allclose(back.positions(meters=True)[:, index], points, rtol=0, atol=TOLERANCE)


@needs_three
@pytest.mark.parametrize("case", IDS)
def test_three_js_draws_every_joint_where_we_do(written, three_page, case):  # noqa: F811
    take, armature, points, path = written[case]
    found = three_positions(three_page, path, key_times(take))
    assert len(found) == armature.nodes
    got = np.stack(list(found.values()), axis=1)  # the skin's joints, in the file's order
    np.testing.assert_allclose(got, points, rtol=0, atol=TOLERANCE)


@pytest.fixture(scope="module")
def blender_found(written, tmp_path_factory):
    jobs = [(path, key_times(take)) for take, _, _, path in written.values()]
    return dict(zip(written, blender_positions(jobs, tmp_path_factory.mktemp("blender"))))


@needs_blender
@pytest.mark.parametrize("case", IDS)
def test_blender_draws_every_joint_where_we_do(written, blender_found, case):
    _, armature, points, _ = written[case]
    found = blender_found[case]
    names = node_names(armature)
    assert sorted(found) == sorted(names)
    got = np.stack([found[n] for n in names], axis=1)
    np.testing.assert_allclose(got, points, rtol=0, atol=TOLERANCE)


@pytest.mark.parametrize("variant", ["z-up", "in mm"])
@pytest.mark.parametrize("path", VARIANT_TAKES, ids=lambda p: p.name)
def test_a_variant_exports_the_same_motion(path, variant):
    """Stood up and in metres: a z-up or millimetre layout of a take is exported as the take is."""
    take = mt.read_take(path)
    armature, points = expected(take)
    other, other_points = expected(VARIANTS[variant](take))
    assert other.up.split()[0] != armature.up.split()[0] or variant == "in mm"
    common = [n for n in armature.names if n in other.names]  # all but the root, renamed under a static one
    assert len(common) >= armature.nodes - 1
    mine, theirs = [armature.names.index(n) for n in common], [other.names.index(n) for n in common]
    np.testing.assert_allclose(other_points[:, theirs], points[:, mine], rtol=0, atol=1e-9)


def test_several_takes_are_several_animations(data_dir, tmp_path):
    takes = [mt.read_take(data_dir / "cmu" / n) for n in ("02_01.amc", "02_02.amc")]
    target = tmp_path / "both.glb"
    mt.export(takes, target)
    document, _ = glb_document(target)
    assert [a["name"] for a in document["animations"]] == ["02_01", "02_02"]
    for i, take in enumerate(takes):
        back = read_gltf(target, animation=i)
        armature, points = expected(take)
        index = [back.skeleton.point_names.index(n) for n in node_names(armature)]
        np.testing.assert_allclose(back.positions(meters=True)[:, index], points, atol=TOLERANCE)
    assert read_gltf(target, animation="02_02").frames == takes[1].frames
    with pytest.raises(ValueError, match="no animation named 'walk'; it has '02_01', '02_02'"):
        read_gltf(target, animation="walk")


def test_text_gltf_holds_the_same_as_glb(data_dir, tmp_path):
    take = mt.read_take(data_dir / "bvh" / "walk01.bvh")
    mt.export(take, tmp_path / "a.glb")
    mt.export(take, tmp_path / "a.gltf")
    text = json.loads((tmp_path / "a.gltf").read_text())
    assert text["buffers"][0]["uri"].startswith("data:application/octet-stream;base64,")
    a, b = read_gltf(tmp_path / "a.glb"), read_gltf(tmp_path / "a.gltf")
    np.testing.assert_array_equal(a.values, b.values)


def test_without_a_body_there_is_no_mesh(data_dir, tmp_path):
    take = mt.read_take(data_dir / "bvh" / "walk01.bvh")
    mt.export(take, tmp_path / "bare.glb", mesh=False)
    document, _ = glb_document(tmp_path / "bare.glb")
    assert "meshes" not in document and len(document["nodes"]) == len(take.skeleton.point_names)


def test_a_rate_resamples_every_take(data_dir, tmp_path):
    take = mt.read_take(data_dir / "cmu" / "02_03.amc")
    mt.export(take, tmp_path / "30.glb", rate=30.0)
    back = read_gltf(tmp_path / "30.glb")
    assert back.frame_rate == 30.0 and back.frames == take.resample(rate=30.0).frames


def test_capsules_face_outwards(data_dir):
    from motiontheater.views.capsules import capsules

    armature, _ = expected(mt.read_take(data_dir / "cmu" / "01_01.amc"))
    body = capsules(armature)
    corners = body.positions[body.triangles]
    faces = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    normals = body.normals[body.triangles].sum(axis=1)
    assert (np.einsum("ij,ij->i", faces, normals) > 0).all()
    assert (body.nodes[body.triangles] == body.nodes[body.triangles][:, :1]).all()  # a capsule follows one node


def _cli(*args, cwd):
    return subprocess.run(
        [sys.executable, "-m", "motiontheater", *map(str, args)], capture_output=True, text=True, cwd=cwd, check=False
    )


def test_export_and_convert_back_on_the_command_line(copies):
    folder = copies("cmu", ["02.asf", "02_01.amc", "02_02.amc"])
    done = _cli("export", "02_01.amc", "02_02.amc", "-o", "out/both.glb", cwd=folder)
    assert done.returncode == 0, done.stderr
    assert "wrote" in done.stdout and (folder / "out" / "both.glb").exists()
    done = _cli("convert", "out/both.glb", "-o", "back.bvh", cwd=folder)
    assert done.returncode == 0, done.stderr
    back, take = mt.read_take(folder / "back.bvh"), mt.read_take(folder / "02_01.amc")
    assert back.frames == take.frames


def test_takes_of_two_skeletons_are_refused_before_writing(copies):
    folder = copies("cmu", ["01.asf", "01_01.amc", "16_15.bvh"])
    done = _cli("export", "01_01.amc", "16_15.bvh", "-o", "both.glb", cwd=folder)
    assert done.returncode == 2
    assert "16_15 has another skeleton than 01_01" in done.stderr and "Traceback" not in done.stderr
    assert not (folder / "both.glb").exists()


def test_batch_exports_a_database_with_a_recipe(copies, tmp_path):
    folder = copies(
        "hdm05", ["HDM_bd.asf", "HDM_bd_hopBothLegs1hops_005_120.amc", "HDM_bd_kickLFront1Reps_003_120.amc"]
    )
    recipe = tmp_path / "export.toml"
    recipe.write_text('[[step]]\nrun = "median"\nsize = 3\n\n[[step]]\nrun = "export"\nmesh = false\n')
    done = _cli("batch", folder, "--recipe", recipe, "-o", tmp_path / "out", "--jobs", "2", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    written = sorted(p.name for p in (tmp_path / "out").glob("*.glb"))
    assert written == ["HDM_bd_hopBothLegs1hops_005_120.glb", "HDM_bd_kickLFront1Reps_003_120.glb"]
    back = read_gltf(tmp_path / "out" / written[0])
    assert back.frames == mt.read_take(folder / "HDM_bd_hopBothLegs1hops_005_120.amc").frames


def test_info_names_every_take_of_a_file(copies):
    folder = copies("cmu", ["02.asf", "02_01.amc", "02_02.amc"])
    assert _cli("export", "02_01.amc", "02_02.amc", "-o", "both.glb", cwd=folder).returncode == 0
    done = _cli("info", "both.glb", cwd=folder)
    assert done.returncode == 0, done.stderr
    assert "takes        2 in the file; this is the first, 02_01; the others: 02_02" in done.stdout
    facts = json.loads(_cli("info", "both.glb", "--json", cwd=folder).stdout)
    assert facts["takes"] == ["02_01", "02_02"]
    assert _cli("export", "02_01.amc", "-o", "one.glb", cwd=folder).returncode == 0
    assert "takes" not in _cli("info", "one.glb", cwd=folder).stdout


def test_a_resampled_export_says_so(copies):
    folder = copies("cmu", ["02.asf", "02_01.amc"])
    done = _cli("export", "02_01.amc", "-o", "30.glb", "--rate", "30", cwd=folder)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "export: 343 frames of 02_01.amc, resampled to 30 Hz: wrote 30.glb"
