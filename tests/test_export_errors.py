"""Bad input to every animation format the export step writes (glTF, GLB, FBX, USD): a clear message
naming what is wrong and no file, not even a partial one."""

import importlib.util
import os

import numpy as np
import pytest

import motiontheater as mt

needs_usd = pytest.mark.skipif(
    importlib.util.find_spec("pxr") is None, reason="usd-core is not installed (pip install usd-core)"
)
SUFFIXES = [".glb", ".gltf", ".fbx", pytest.param(".usda", marks=needs_usd), pytest.param(".usdc", marks=needs_usd)]


@pytest.mark.parametrize("suffix", SUFFIXES)
def test_bad_takes_get_a_message_and_no_file(data_dir, tmp_path, suffix):
    take = mt.read_take(data_dir / "bvh" / "walk01.bvh")
    holed = take.values.copy()
    holed[10:20, 5] = np.nan
    with pytest.raises(ValueError, match="NaN or inf values; fill the gaps first"):
        mt.export(take.replace(values=holed), tmp_path / f"nan{suffix}")
    lone = mt.Skeleton(bones=(), hierarchy=(("root", ()),), convention="bvh")
    with pytest.raises(ValueError, match="a root and no bone"):
        mt.export(mt.Motion(lone, np.zeros((3, 6))), tmp_path / f"one{suffix}")
    bad = take.skeleton.bones[0].name
    renamed = take.skeleton.__class__(
        bones=tuple(
            b if b.name != bad else b.__class__(**{**b.__dict__, "name": "bad\udcff"}) for b in take.skeleton.bones
        ),
        hierarchy=tuple(
            (p if p != bad else "bad\udcff", tuple(c if c != bad else "bad\udcff" for c in cs))
            for p, cs in take.skeleton.hierarchy
        ),
        root=take.skeleton.root,
        convention="bvh",
    )
    with pytest.raises(ValueError, match="is not UTF-8 text"):
        mt.export(take.replace(skeleton=renamed), tmp_path / f"name{suffix}")
    assert sorted(os.listdir(tmp_path)) == []


@pytest.mark.parametrize("suffix", SUFFIXES)
def test_an_unwritable_target_is_named(data_dir, tmp_path, suffix):
    take = mt.read_take(data_dir / "bvh" / "walk01.bvh")
    (tmp_path / "a file").write_text("")
    target = tmp_path / "a file" / f"a{suffix}"
    with pytest.raises(OSError, match=f"cannot write {target}"):
        mt.export(take, target)
    assert os.listdir(tmp_path) == ["a file"]


@pytest.mark.parametrize("suffix", [".fbx", ".usdc"])
def test_a_file_only_written_is_said_not_to_be_read(data_dir, tmp_path, capsys, suffix):
    from motiontheater.cli import main

    target = tmp_path / f"a{suffix}"
    target.write_bytes(b"")
    assert main(["info", str(target)]) == 2
    said = capsys.readouterr().err
    assert "writes" in said and "(the export step) but does not read it" in said and "Traceback" not in said
