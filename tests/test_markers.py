"""Virtual markers: C3D read back through c3d and ezc3d, TRC read by OpenSim's rules."""

import sys
import warnings

import numpy as np
import pytest

import motiontheater as mt
from corpus import ids, real_files
from motiontheater.cli import main
from motiontheater.views.markers import c3d_points, write_c3d

TAKES = real_files("cmu/01_01.amc") + real_files("cmu/01_01.bvh") + real_files("bvh/walk01.bvh")


def read(path) -> mt.Motion:
    path = str(path)
    return mt.read_bvh(path) if path.endswith(".bvh") else mt.read_amc(path, mt.read_asf(mt.skeleton_path_for(path)))


def float32_bound(expected_mm: np.ndarray) -> np.ndarray:
    """What float32 storage allows: 1e-4 mm, or half a float32 step where that is larger
    (points more than 2.048 m from the origin)."""
    return np.maximum(1e-4, np.spacing(np.abs(expected_mm).astype(np.float32)).astype(float) / 2)


def read_with_c3d(path):
    c3d = pytest.importorskip("c3d", reason="c3d is not installed (pip install 'motiontheater[c3d]')")
    with open(path, "rb") as f, warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # "No analog data found": none was written
        reader = c3d.Reader(f)
        frames = np.array([points for _, points, _ in reader.read_frames()])
        labels = [label.strip() for label in reader.point_labels]
        meta = dict(
            rate=reader.point_rate,
            units=reader.get("POINT:UNITS").string_value.strip(),
            first=reader.first_frame,
            screen=(reader.get("POINT:X_SCREEN").string_value, reader.get("POINT:Y_SCREEN").string_value),
        )
    return frames, labels, meta


@pytest.mark.parametrize("path", TAKES, ids=ids(TAKES))
def test_c3d_reads_back_through_both_libraries(tmp_path, path):
    motion = read(path)
    target = tmp_path / "take.c3d"
    write_c3d(motion, target)
    expected = motion.positions(meters=True) * 1000.0
    frames, labels, meta = read_with_c3d(target)
    assert labels == list(motion.skeleton.point_names)
    rate = float(np.float32(motion.frame_rate))  # C3D stores it as float32
    assert meta == dict(rate=rate, units="mm", first=motion.first_frame, screen=("+X", "+Y"))
    assert frames.shape == (motion.frames, len(labels), 5)
    got = frames[..., :3]
    assert np.array_equal(got, expected.astype(np.float32))  # exactly float32 storage of Motion.positions()
    assert (np.abs(got - expected) <= float32_bound(expected)).all()
    assert (frames[..., 3] == 0).all()
    ezc3d = pytest.importorskip("ezc3d", reason="ezc3d is not installed")
    c = ezc3d.c3d(str(target))
    points = np.moveaxis(c["data"]["points"][:3], (0, 1, 2), (2, 1, 0))
    assert (np.abs(points - expected) <= float32_bound(expected)).all()
    assert list(c["parameters"]["POINT"]["LABELS"]["value"]) == labels
    assert c["parameters"]["POINT"]["RATE"]["value"][0] == rate
    assert c["parameters"]["POINT"]["UNITS"]["value"] == ["mm"]


def test_c3d_within_1e_4_mm_near_the_origin(tmp_path):
    """Below 2.048 m from the origin float32 holds millimetres to 1e-4."""
    path = next(iter(real_files("cmu/01_01.amc")), None)
    if path is None:
        pytest.skip("CMU 01_01 not in the corpus")
    motion = read(path)
    write_c3d(motion, tmp_path / "take.c3d")
    frames, _, _ = read_with_c3d(tmp_path / "take.c3d")
    expected = motion.positions(meters=True) * 1000.0
    near = np.abs(expected) < 2048
    assert near.mean() > 0.9
    assert np.abs(frames[..., :3] - expected)[near].max() <= 1e-4


def test_missing_samples_are_marked(tmp_path):
    path = next(iter(real_files("bvh/walk01.bvh")), None)
    if path is None:
        pytest.skip("walk01.bvh not in the corpus")
    motion = read(path)
    values = motion.values.copy()
    values[7, motion.columns("LeftArm")[0]] = np.nan  # the points that the arm's rotation moves go missing
    motion = motion.replace(values=values)
    below = np.flatnonzero(~np.isfinite(motion.positions()[7]).all(axis=1))
    assert len(below) >= 2
    points = c3d_points(motion)
    assert (points[7, below, 3] == -1).all() and (points[7, below, :3] == 0).all()
    assert (np.delete(points[7], below, axis=0)[:, 3] == 0).all()
    write_c3d(motion, tmp_path / "gap.c3d")
    frames, _, _ = read_with_c3d(tmp_path / "gap.c3d")
    assert (frames[7, below, 3] == -1).all()
    assert (frames[6, :, 3] == 0).all() and (frames[8, :, 3] == 0).all()
    ezc3d = pytest.importorskip("ezc3d", reason="ezc3d is not installed")
    read_back = ezc3d.c3d(str(tmp_path / "gap.c3d"))["data"]["points"]
    assert np.isnan(read_back[:3, below, 7]).all()
    assert np.isfinite(read_back[:3, :, 8]).all()


def test_c3d_refuses_an_empty_motion(tmp_path):
    motion = read(TAKES[0]) if TAKES else pytest.skip("no corpus")
    with pytest.raises(ValueError, match="at least one frame"):
        write_c3d(motion.replace(values=motion.values[:0]), tmp_path / "empty.c3d")
    assert not list(tmp_path.iterdir())


def read_trc_as_opensim(path) -> tuple[dict, list[str], np.ndarray, np.ndarray]:
    """A TRC read by the rules of OpenSim's TRCFileAdapter::extendRead: header keys, marker
    and X1 Y1 Z1 labels, data from line 6 after blank lines, rows of 2 + 3 * NumMarkers
    tab-separated fields, an empty field a missing coordinate."""
    with open(path, encoding="utf-8") as f:
        lines = f.read().split("\n")
    tokens = [[t for t in line.replace("\r", "").split("\t")] for line in lines]
    assert lines[0].split()[0] == "PathFileType"
    keys = [t for t in tokens[1] if t]
    assert keys == [
        "DataRate",
        "CameraRate",
        "NumFrames",
        "NumMarkers",
        "Units",
        "OrigDataRate",
        "OrigDataStartFrame",
        "OrigNumFrames",
    ]
    values = [t for t in tokens[2] if t]
    header = dict(zip(keys, values, strict=True))
    markers = int(header["NumMarkers"])
    labels = [t for t in tokens[3] if t]
    assert len(labels) == markers + 2 and labels[:2] == ["Frame#", "Time"]
    xyz = [t for t in tokens[4] if t]
    assert xyz[: 3 * markers] == [f"{a}{i}" for i in range(1, markers + 1) for a in "XYZ"]
    row = 5
    while row < len(lines) and not lines[row].strip():
        row += 1
    times, data = [], []
    while row < len(lines) and lines[row]:
        fields = tokens[row]
        assert len(fields) == 2 + 3 * markers, f"line {row + 1}"
        times.append(float(fields[1]))
        data.append([float(v) if v else np.nan for v in fields[2:]])
        row += 1
    return header, labels[2:], np.array(times), np.array(data).reshape(len(data), markers, 3)


@pytest.mark.parametrize("path", TAKES, ids=ids(TAKES))
def test_trc_opens_by_opensims_rules(tmp_path, path, capsys):
    motion = read(path)
    target = tmp_path / "take.trc"
    assert main(["positions", str(path), "-o", str(target), "--meters"]) == 0
    assert "to " + str(target) in capsys.readouterr().out
    header, labels, times, data = read_trc_as_opensim(target)
    assert header["Units"] == "m"
    assert float(header["DataRate"]) == pytest.approx(motion.frame_rate, rel=1e-5)  # written with %g
    assert int(header["NumFrames"]) == motion.frames == len(times)
    assert labels == list(motion.skeleton.point_names)  # a BVH's root as its file names it, as in its C3D
    np.testing.assert_allclose(data, motion.positions(meters=True), rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(times, motion.times, rtol=1e-9)


def test_cli_markers_to_c3d(tmp_path, capsys):
    if not TAKES:
        pytest.skip("no corpus")
    target = tmp_path / "take.c3d"
    assert main(["c3d", str(TAKES[-1]), "-o", str(target)]) == 0
    assert "c3d: wrote" in capsys.readouterr().out
    _, labels, _ = read_with_c3d(target)
    assert len(labels) == len(read(TAKES[-1]).skeleton.point_names)


def test_missing_c3d_library_is_one_line(tmp_path, capsys, monkeypatch):
    if not TAKES:
        pytest.skip("no corpus")
    monkeypatch.setitem(sys.modules, "c3d", None)
    assert main(["c3d", str(TAKES[-1]), "-o", str(tmp_path / "take.c3d")]) == 2
    err = capsys.readouterr().err.strip()
    assert err == "motiontheater c3d: writing C3D files needs c3d: pip install 'motiontheater[c3d]'"
    assert not list(tmp_path.iterdir())
