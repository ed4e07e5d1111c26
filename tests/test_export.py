"""Position export: CSV, NPZ and TRC files and the positions command."""

import numpy as np
import pytest

import motiontheater as mt
from motiontheater.cli import main


@pytest.fixture
def motion(data_dir):
    return mt.read_amc(data_dir / "cmu" / "02_01.amc", mt.read_asf(data_dir / "cmu" / "02.asf"))


def test_csv(motion, tmp_path):
    mt.write_positions(motion, tmp_path / "p.csv")
    lines = (tmp_path / "p.csv").read_text().splitlines()
    header = lines[0].split(",")
    assert header[:5] == ["frame", "time [s]", "root.x [in/0.45]", "root.y [in/0.45]", "root.z [in/0.45]"]
    assert header[-1] == f"{motion.skeleton.bone_names[-1]}.z [in/0.45]"
    table = np.loadtxt(tmp_path / "p.csv", delimiter=",", skiprows=1)
    assert table.shape == (motion.frames, 2 + 3 * 31)
    np.testing.assert_array_equal(table[:, 0], np.arange(1, motion.frames + 1))
    np.testing.assert_allclose(table[:, 1], np.arange(motion.frames) / 120, rtol=1e-9)
    np.testing.assert_allclose(table[:, 2:].reshape(-1, 31, 3), motion.positions(), rtol=1e-9, atol=1e-9)


def test_npz_is_exact(motion, tmp_path):
    mt.write_positions(motion, tmp_path / "p.npz", meters=True)
    data = np.load(tmp_path / "p.npz")
    np.testing.assert_array_equal(data["positions"], motion.positions(meters=True))
    assert list(data["joint_names"]) == list(motion.skeleton.joint_names)
    assert data["frame_rate"] == 120 and data["meters_per_unit"] == 1.0


def test_trc(motion, tmp_path):
    mt.write_positions(motion, tmp_path / "p.trc", meters=True)
    lines = (tmp_path / "p.trc").read_text().split("\n")
    assert lines[0] == "PathFileType\t4\t(X/Y/Z)\tp.trc"
    assert lines[2].split("\t") == ["120", "120", str(motion.frames), "31", "m", "120", "1", str(motion.frames)]
    assert lines[3].split("\t")[:5] == ["Frame#", "Time", "root", "", ""]
    assert lines[4].split("\t")[2:5] == ["X1", "Y1", "Z1"] and lines[5] == ""
    table = np.loadtxt(tmp_path / "p.trc", skiprows=6)
    np.testing.assert_allclose(table[:, 2:].reshape(-1, 31, 3), motion.positions(meters=True), rtol=1e-9, atol=1e-12)


def test_trc_needs_a_named_unit(motion, tmp_path):
    with pytest.raises(ValueError, match="TRC needs a named length unit"):
        mt.write_positions(motion, tmp_path / "p.trc")
    assert not (tmp_path / "p.trc").exists()


def test_positions_command(data_dir, tmp_path, capsys):
    out = tmp_path / "walk.npz"
    assert (
        main(
            [
                "positions",
                str(data_dir / "cmu" / "02.asf"),
                str(data_dir / "cmu" / "02_01.amc"),
                "-o",
                str(out),
                "--meters",
            ]
        )
        == 0
    )
    assert (
        capsys.readouterr().out.strip() == f"positions: wrote 343 frames of {data_dir / 'cmu' / '02_01.amc'} to {out}"
    )
    assert np.load(out)["positions"].shape == (343, 31, 3)


def test_positions_command_fails_cleanly(data_dir, tmp_path, capsys):
    out = tmp_path / "bad.csv"
    assert (
        main(["positions", str(data_dir / "cmu" / "01.asf"), str(data_dir / "edge" / "test.amc"), "-o", str(out)]) == 2
    )
    err = capsys.readouterr().err
    assert err.startswith("motiontheater positions: ") and "test.amc, line 4: unknown bone 'Head'" in err
    assert not out.exists() and list(tmp_path.iterdir()) == []


def test_bvh_headers_carry_its_detected_unit(data_dir, tmp_path):
    walk = mt.read_bvh(data_dir / "bvh" / "walk01.bvh")  # 185 units tall: centimetres
    mt.write_positions(walk, tmp_path / "w.trc")
    assert (tmp_path / "w.trc").read_text().split("\n")[2].split("\t")[4] == "cm"
    mt.write_positions(walk, tmp_path / "w.csv")
    assert (tmp_path / "w.csv").read_text().split("\n")[0].split(",")[2] == "Hips.x [cm]"  # its root's name
    mt.write_positions(walk, tmp_path / "w.npz")
    data = np.load(tmp_path / "w.npz")
    assert data["meters_per_unit"] == 0.01 and str(data["length_unit"]) == "cm"
    zombie = mt.read_bvh(data_dir / "bvh" / "zombie.bvh")  # 45 units tall along z: inches
    mt.write_positions(zombie, tmp_path / "z.trc")
    assert (tmp_path / "z.trc").read_text().split("\n")[2].split("\t")[4] == "in"


def test_converted_motions_keep_their_unit_in_headers(motion, tmp_path):
    bvh = mt.to_bvh(motion)  # CMU's inch/0.45 goes with it
    mt.write_positions(bvh, tmp_path / "b.csv")
    assert (tmp_path / "b.csv").read_text().split("\n")[0].split(",")[2] == "root.x [in/0.45]"
    with pytest.raises(ValueError, match="TRC needs a named length unit"):
        mt.write_positions(bvh, tmp_path / "b.trc")
    mt.write_positions(bvh, tmp_path / "b.trc", meters=True)
    table = np.loadtxt(tmp_path / "b.trc", skiprows=6)
    np.testing.assert_allclose(table[:, 2:5], motion.positions(meters=True)[:, 0], rtol=1e-9)


def test_positions_command_takes_a_unit(data_dir, tmp_path, capsys):
    out = tmp_path / "walk.trc"
    assert main(["positions", str(data_dir / "bvh" / "walk01.bvh"), "-o", str(out), "--unit", "mm"]) == 0
    assert out.read_text().split("\n")[2].split("\t")[4] == "mm"
    assert capsys.readouterr().err == ""
    assert main(["positions", str(data_dir / "bvh" / "sinusoidal.bvh"), "-o", str(tmp_path / "r.csv"), "--meters"]) == 0
    assert "the length unit of the input was assumed (cm)" in capsys.readouterr().err
    assert main(["positions", str(data_dir / "bvh" / "walk01.bvh"), "-o", str(out), "--unit", "ells"]) == 2
    assert "unknown length unit 'ells'" in capsys.readouterr().err
