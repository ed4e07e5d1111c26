"""Every BVH the project writes, read by the BVH readers on PyPI: the same joints, the same
hierarchy and the same joint positions as ``motion.positions()`` of the take written.

Each reader computes the positions its own way: bvhio with its transform hierarchy (PyGLM),
bvh-toolbox with the forward kinematics of its ``bvh2csv`` converter, and python-bvh (``bvh``),
which only parses, through the small forward kinematics below (independent of ours: 3x3 matrices
per channel, in the file's channel order). omimo's PyMO is not on PyPI (the ``pymo`` there is a
MongoDB helper), so it cannot be a test dependency: its test skips and says so.

The written numbers are the shortest text that reads back as the same double, so the file costs
no precision: the bound is forward-kinematics arithmetic alone, 1e-6 of the figure's size (the
widest extent of its first frame). bvhio computes in single precision (PyGLM's vec3 and quat),
whose rounding grows with the coordinates rather than the figure: for it, 1e-6 of the larger of
the figure's size and the farthest coordinate.

The readers are slow pure Python, so each take is written with a few of its frames (the first, the
middle one and the last two); a take written unchanged is its file's very bytes (test_bvh.py), so
what the writer itself lays out is the text of a changed take, which these are.
"""

from __future__ import annotations

import functools
import importlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

import motiontheater as mt
from corpus import real_files
from test_convert import every_joint_moves, stretching_bones
from variants import with_offset_channels, with_static_root

BVHS = real_files("*/*.bvh")
AMCS = real_files("*/*.amc")
# Valid BVH that a reader gets wrong: (takes, reader, its bug).
READER_BUGS = [
    (
        ("bvhTools_test3.bvh", "static root", "static root, z-up", "every joint moves"),
        "bvh-toolbox",
        "bvh-toolbox 0.1.3 puts every joint but the root at its OFFSET, ignoring its position channels",
    ),
    (
        ("amc-bvh, bones that stretch",),
        "bvh-toolbox",
        "bvh-toolbox 0.1.3 raises KeyError on a joint with position channels and no rotation channel "
        "(its Euler order is then ''), and ignores those position channels besides",
    ),
]


@dataclass
class Reading:
    """What a reader made of a file: its points (joints, then End Sites named ``<joint>_End``),
    each one's parent (None for the root), and their positions, (frames, points, 3)."""

    names: list[str]
    parents: dict[str, str | None]
    positions: np.ndarray
    precision: str = "double"  # or "single"
    ends_known: bool = True  # False: the reader gives every leaf a tip, End Site or not


def read_with_bvhio(path: Path) -> Reading:
    bvhio = pytest.importorskip("bvhio", reason="bvhio is a test dependency: pip install -e '.[test]'")
    glm = pytest.importorskip("glm", reason="PyGLM comes with bvhio")
    root = bvhio.readAsHierarchy(str(path))
    declared = {j.Name: j for j, _, _ in bvhio.readAsBvh(str(path), loadKeyFrames=False).Root.layout()}
    joints = [j for j, _, _ in root.layout()]
    names, parents = [], {}
    for joint in joints:
        names.append(joint.Name)
        parents[joint.Name] = joint.Parent.Name if joint.Parent is not None else None
        if not joint.Children:
            names.append(f"{joint.Name}_End")
            parents[f"{joint.Name}_End"] = joint.Name
    frames = []
    for frame in range(root.getKeyframeRange()[1] + 1):
        root.loadPose(frame, recursive=True)
        points = []
        for joint in joints:
            points.append(list(joint.PositionWorld))
            if not joint.Children:
                # the End Site's offset is in the BVH joint's frame; bvhio turns each joint's frame
                # by the rest rotation that points its bone along y
                bvh_joint = declared[joint.Name]
                points.append(list(joint.pointToWorld(glm.inverse(bvh_joint.getRotation()) * bvh_joint.EndSite)))
        frames.append(points)
    return Reading(names, parents, np.array(frames, dtype=float), precision="single", ends_known=False)


def read_with_bvh_toolbox(path: Path) -> Reading:
    toolbox = pytest.importorskip(
        "bvhtoolbox",
        reason="bvhtoolbox (and setuptools<82, whose pkg_resources it imports) are test dependencies: pip install -e '.[test]'",
    )
    csv = importlib.import_module("bvhtoolbox.convert.bvh2csv")
    tree = toolbox.BvhTree(path.read_text())
    written = {}

    class Numpy:
        """numpy as bvh2csv sees it, but savetxt keeps the table instead of printing 5 decimals."""

        def __getattr__(self, name):
            return getattr(np, name)

        def savetxt(self, _file, data, header, **_):
            written.update(data=data, header=header)

    real, csv.np = csv.np, Numpy()
    try:
        csv.write_joint_positions(tree, "unused.csv", end_sites=True)
    finally:
        csv.np = real
    names = [column[: -len(".x")] for column in written["header"].split(",")[1::3]]
    parents = {}
    for node in tree.get_joints(end_sites=True):
        parent = tree.joint_parent(node.name)
        parents[node.name] = parent.name if parent is not None else None
    return Reading(names, parents, written["data"][:, 1:].reshape(tree.nframes, len(names), 3))


def read_with_python_bvh(path: Path) -> Reading:
    bvh = pytest.importorskip("bvh", reason="bvh (python-bvh) is a test dependency: pip install -e '.[test]'")
    parsed = bvh.Bvh(path.read_text())
    joints = parsed.get_joints()
    names, parents, frames = [], {}, []
    for joint in joints:
        names.append(joint.name)
        parent = parsed.joint_parent(joint.name)
        parents[joint.name] = parent.name if parent is not None else None
        for _ in joint.filter("End"):
            names.append(f"{joint.name}_End")
            parents[f"{joint.name}_End"] = joint.name
    layout = {j.name: (parsed.joint_channels(j.name), parsed.get_joint_channels_index(j.name)) for j in joints}
    for frame in range(parsed.nframes):
        world, points = {}, []
        for joint in joints:
            channels, first = layout[joint.name]
            values = [float(v) for v in parsed.frames[frame][first : first + len(channels)]]
            local = np.eye(4)
            local[:3, 3] = parsed.joint_offset(joint.name)
            for channel, value in zip(channels, values, strict=True):
                axis = "XYZ".index(channel[0])
                if channel.endswith("position"):  # replaces that part of the OFFSET
                    local[axis, 3] = value
                else:  # intrinsic: each turn about the axes already turned
                    local[:3, :3] = local[:3, :3] @ _turn(axis, value)
            parent = parents[joint.name]
            world[joint.name] = local if parent is None else world[parent] @ local
            points.append(world[joint.name][:3, 3])
            for end in joint.filter("End"):
                points.append(world[joint.name][:3, :3] @ [float(v) for v in end["OFFSET"]] + world[joint.name][:3, 3])
        frames.append(points)
    return Reading(names, parents, np.array(frames))


def _turn(axis: int, degrees: float) -> np.ndarray:
    c, s = np.cos(np.radians(degrees)), np.sin(np.radians(degrees))
    return np.array(
        [
            [[1, 0, 0], [0, c, -s], [0, s, c]],
            [[c, 0, s], [0, 1, 0], [-s, 0, c]],
            [[c, -s, 0], [s, c, 0], [0, 0, 1]],
        ][axis]
    )


READERS = {
    "bvhio": read_with_bvhio,
    "bvh-toolbox": read_with_bvh_toolbox,
    "python-bvh": read_with_python_bvh,
}


def few_frames(motion: mt.Motion) -> mt.Motion:
    """The first frame, the middle one and the last two, as a take of their own."""
    n = motion.frames
    chosen = sorted({0, n // 2, max(0, n - 2), n - 1})
    return motion.replace(values=motion.values[chosen])


def points_of(skeleton: mt.Skeleton) -> dict[str, str | None]:
    """Each point's parent by the names a BVH file shows (the root by its own name)."""
    root = skeleton.root.name
    return {
        name: None if name == root else (root if skeleton.parent(name) == "root" else skeleton.parent(name))
        for name in skeleton.point_names
    }


def assert_read_alike(motion: mt.Motion, path: Path, reader: str) -> None:
    reading = READERS[reader](path)
    ours = points_of(motion.skeleton)
    if reading.ends_known:
        assert reading.parents == ours
    else:
        joints = {
            n: p for n, p in ours.items() if n == motion.skeleton.root.name or not motion.skeleton.bone(n).end_site
        }
        assert {n: p for n, p in reading.parents.items() if n in joints} == joints
        assert set(ours) <= set(reading.parents)
    expected = motion.positions()
    size = float(np.ptp(expected[0], axis=0).max())
    scale = max(size, float(np.abs(expected).max())) if reading.precision == "single" else size
    names = list(motion.skeleton.point_names)
    got = reading.positions[:, [reading.names.index(n) for n in names]]
    assert got.shape == expected.shape
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-6 * scale)


def cases(names_or_paths):
    """(take, reader) pairs, each marked with the reader's bug where it is wrong on that valid file."""
    params = []
    for take in names_or_paths:
        name = take if isinstance(take, str) else take.name
        for reader in READERS:
            bug = next((why for takes, wrong, why in READER_BUGS if reader == wrong and name in takes), None)
            marks = pytest.mark.xfail(strict=True, reason=bug) if bug else ()
            params.append(pytest.param(take, reader, marks=marks, id=f"{name}-{reader}"))
    return params


@pytest.mark.parametrize("path,reader", cases(BVHS))
def test_every_real_bvh_written(path, reader, tmp_path):
    take = few_frames(mt.read_bvh(path))
    mt.write_bvh(take, tmp_path / "w.bvh")
    assert_read_alike(take, tmp_path / "w.bvh", reader)


@pytest.mark.parametrize("path,reader", cases(AMCS))
def test_every_real_amc_converted(path, reader, tmp_path):
    take = few_frames(mt.read_amc(path, mt.read_asf(mt.skeleton_path_for(path))))
    bvh = mt.to_bvh(take)
    mt.write_bvh(bvh, tmp_path / "w.bvh")
    assert_read_alike(bvh, tmp_path / "w.bvh", reader)


@functools.cache
def derived(data: Path) -> dict[str, mt.Motion]:
    walk = mt.read_bvh(data / "bvh" / "walk01.bvh")
    cmu = mt.read_bvh(data / "cmu" / "01_01.bvh")
    amc = mt.read_amc(data / "cmu" / "02_01.amc", mt.read_asf(data / "cmu" / "02.asf"))
    return {
        "filtered": walk.median(size=5),
        "resampled": cmu.resample(rate=50),
        "bvh-asf-bvh": mt.to_bvh(mt.to_asf(walk)),
        "static root": with_static_root(walk),
        "static root, z-up": with_static_root(walk, turn=(90, 0, 0), shift=(10, -20, 5)),
        "offset channels": with_offset_channels(walk),
        "every joint moves": every_joint_moves(walk),
        "amc-bvh, bones that stretch": mt.to_bvh(stretching_bones(amc)),
        "amc-bvh, XYZ": mt.to_bvh(amc, "XYZ"),
        "retargeted": mt.retarget(amc, walk.skeleton, cleanup=False),
        "in metres": walk.to_meters(),
    }


DERIVED = [
    "filtered",
    "resampled",
    "bvh-asf-bvh",
    "static root",
    "static root, z-up",
    "offset channels",
    "every joint moves",
    "amc-bvh, bones that stretch",
    "amc-bvh, XYZ",
    "retargeted",
    "in metres",
]


@pytest.mark.parametrize("kind,reader", cases(DERIVED))
def test_derived_takes(data_dir, kind, reader, tmp_path):
    take = few_frames(derived(data_dir)[kind])
    mt.write_bvh(take, tmp_path / "w.bvh")
    assert_read_alike(take, tmp_path / "w.bvh", reader)


def test_pymo():
    pytest.skip(
        "omimo's PyMO has no distribution on PyPI (the 'pymo' there is a MongoDB helper), so it cannot be a "
        "test dependency; the readers here are bvhio, bvh-toolbox and python-bvh"
    )


def test_a_changed_take_ends_its_last_line(data_dir, tmp_path):
    """python-bvh drops a last line without a line break; a take written unchanged stays as found."""
    path = data_dir / "bvh" / "sinusoidal.bvh"
    assert not path.read_bytes().endswith(b"\n")
    take = mt.read_bvh(path)
    mt.write_bvh(take, tmp_path / "same.bvh")
    assert (tmp_path / "same.bvh").read_bytes() == path.read_bytes()
    mt.write_bvh(take.median(size=3), tmp_path / "changed.bvh")
    assert (tmp_path / "changed.bvh").read_bytes().endswith(b" 0 0 0 0 0\n")
