"""The format table: a format is its codec module and one row, found by everything that reads or
writes takes by their names."""

import io
import json
import os
from pathlib import Path

import numpy as np
import pytest

import motiontheater as mt
from motiontheater._io import PLAIN
from motiontheater.cli import main
from motiontheater.formats import table


def read_toy(path, skeleton, frame_rate, unit, workers):
    """A toy codec: a BVH's text behind a line that names the toy format."""
    text = Path(path).read_bytes()
    if not text.startswith(b"TOY\n"):
        raise mt.FormatError(os.fspath(path), 1, "a toy file begins with TOY")
    return mt.read_bvh(io.BytesIO(text[4:]), unit=unit)


def write_toy(motion, path):
    text = io.BytesIO()
    mt.write_bvh(motion, text)
    Path(path).write_bytes(b"TOY\n" + text.getvalue())


@pytest.fixture
def toy_format(monkeypatch):
    """One row more in the table, as a new format's module would add."""
    monkeypatch.setitem(table.FORMATS, ".toy", table.Format(".toy", "Toy", "bvh", read_toy, write_toy))


@pytest.fixture
def toy_take(data_dir, tmp_path):
    folder = tmp_path / "takes"
    folder.mkdir()
    path = folder / "walk.toy"
    path.write_bytes(b"TOY\n" + (data_dir / "bvh" / "walk01.bvh").read_bytes())
    return path


def test_a_format_is_one_row_read_take_reads_it(toy_format, toy_take, data_dir):
    motion = mt.read_take(toy_take)
    np.testing.assert_array_equal(motion.values, mt.read_bvh(data_dir / "bvh" / "walk01.bvh").values)
    assert ".toy" in table.take_suffixes()
    with pytest.raises(ValueError, match=r"walk\.txt: a take's file name must end in .amc, .bvh, .glb, .gltf or .toy"):
        table.format_of("walk.txt")


def test_a_new_format_is_converted_batched_and_described(toy_format, toy_take, tmp_path, capsys):
    # convert: a toy take (BVH convention) to AMC, and back through the toy writer
    assert main(["convert", str(toy_take), "-o", str(tmp_path / "walk.amc")]) == 0
    assert (tmp_path / "walk.asf").exists()
    assert main(["median", str(toy_take), "--size", "3", "-o", str(tmp_path / "smooth.toy")]) == 0
    assert (tmp_path / "smooth.toy").read_bytes().startswith(b"TOY\n")
    np.testing.assert_array_equal(
        mt.read_take(tmp_path / "smooth.toy").values, mt.read_take(toy_take).median(size=3).values
    )
    # batch finds it in a folder
    capsys.readouterr()
    assert main(["batch", "--median", "3", str(toy_take.parent), "-o", str(tmp_path / "out")]) == 0
    assert "1 processed" in capsys.readouterr().out
    assert (tmp_path / "out" / "walk.bvh").exists()  # a motion of BVH convention is written as .bvh
    # info names it
    assert main(["info", str(toy_take), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["format"] == "Toy"


def test_the_skeleton_reader_parses_a_file_of_the_same_bytes_once(data_dir, tmp_path):
    copy = tmp_path / "01.asf"
    copy.write_bytes((data_dir / "cmu" / "01.asf").read_bytes())
    assert table.read_skeleton(copy) is table.read_skeleton(data_dir / "cmu" / "01.asf")
    assert table.read_skeleton(copy, "cm") is not table.read_skeleton(copy)  # a unit given is another skeleton
    copy.write_bytes(copy.read_bytes().replace(b"lfemur", b"lfemux"))
    assert "lfemux" in table.read_skeleton(copy).joint_names  # a changed file is read again
    with pytest.raises(ValueError, match=r"x\.amc: a skeleton's file name must end in .asf or .bvh"):
        table.read_skeleton(tmp_path / "x.amc")
    with pytest.raises(FileNotFoundError, match=r"nothere\.asf: no such file"):
        table.read_skeleton(tmp_path / "nothere.asf")


def test_each_convention_has_its_suffix_and_companion():
    assert table.suffix_for("asf") == ".amc" and table.suffix_for("bvh") == ".bvh"
    assert table.skeleton_for("x/02_01.amc", "x/02.asf") == Path("x/02.asf")
    assert table.skeleton_for("x/walk.bvh", "x/02.asf") is None  # a BVH holds its own
    assert not table.states_unit("walk.BVH") and table.states_unit("walk.amc") and table.states_unit("p.csv")
    with pytest.raises(ValueError, match="no format writes motions of 'fbx' skeletons"):
        table.suffix_for("fbx")


@pytest.mark.parametrize(
    "name", ["cmu/01_01.amc", "hdm05/HDM_bd_lieDownFloor_004_120.amc", "bvh/walk01.bvh", "cmu/16_15.bvh"]
)
def test_a_take_read_without_its_layout_is_the_same_motion(data_dir, name):
    """layout=False (a take looked at, not written back) reads the same values, header, rate and
    frames, and leaves out only how the text is laid out: the plain style, no line order."""
    path = data_dir / name
    whole, cut = table.read_take_frames(path)
    bare, bare_cut = table.read_take_frames(path, layout=False)
    assert cut is None and bare_cut is None
    np.testing.assert_array_equal(bare.values, whole.values)
    assert (bare.frame_rate, bare.first_frame, bare.header) == (whole.frame_rate, whole.first_frame, whole.header)
    assert bare.skeleton.joint_names == whole.skeleton.joint_names
    assert (bare.style, bare.line_order) == (PLAIN, None)
    if name.endswith(".amc"):
        assert whole.line_order  # the file's own: the AMC reader keeps it where layout is read
