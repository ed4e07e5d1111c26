"""Variants of real files (units, orders, layout, line endings) read to the same motion."""

import re
from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import motiontheater as mt

CMU = "cmu/01_01.amc", "cmu/01.asf"


@pytest.fixture
def original(data_dir):
    amc, asf = (data_dir / p for p in CMU)
    return asf.read_bytes(), amc.read_bytes()


def read(tmp_path, asf_bytes, amc_bytes):
    (tmp_path / "v.asf").write_bytes(asf_bytes)
    (tmp_path / "v.amc").write_bytes(amc_bytes)
    skeleton = mt.read_asf(tmp_path / "v.asf")
    return mt.read_amc(tmp_path / "v.amc", skeleton)


def by_channel(motion):
    return {c: motion.values[:, i] for i, c in enumerate(motion.channels)}


def assert_same_motion(a, b, rtol=0.0):
    ca, cb = by_channel(a), by_channel(b)
    assert set(ca) == set(cb)
    for c in ca:
        np.testing.assert_allclose(ca[c], cb[c], rtol=rtol, atol=0, err_msg=str(c))


def test_crlf_lf_cr_and_tabs(original, tmp_path):
    asf, amc = original
    reference = read(tmp_path, asf, amc)
    for newline in (b"\n", b"\r\n", b"\r"):
        for blank in (b" ", b"\t", b" \t "):

            def variant(text, newline=newline, blank=blank):
                lines = re.split(rb"\r\n|\r|\n", text)
                return newline.join(blank.join(line.split(b" ")) for line in lines)

            motion = read(tmp_path, variant(asf), variant(amc))
            # :documentation is free text: its blanks are content
            assert replace(motion.skeleton, documentation=()) == replace(reference.skeleton, documentation=())
            assert motion.values.tobytes() == reference.values.tobytes()


def test_angles_in_radians(original, tmp_path):
    """angle rad: the ASF's angles and the AMC's rotations converted, the same motion."""
    reference = read(tmp_path, *original)
    rad = reference.to_radians()
    mt.write_asf(rad.skeleton, tmp_path / "rad.asf")
    mt.write_amc(rad, tmp_path / "rad.amc")
    assert b"angle rad" in (tmp_path / "rad.asf").read_bytes()
    assert b":RADIANS" in (tmp_path / "rad.amc").read_bytes()
    again = mt.read_amc(tmp_path / "rad.amc", mt.read_asf(tmp_path / "rad.asf"))
    assert again.skeleton.angle_unit == "rad"
    assert_same_motion(again.to_degrees(), reference, rtol=1e-14)
    assert again.skeleton.bone("lfemur").limits[0] == pytest.approx((np.radians(-160), np.radians(20)))


def test_another_root_order(original, tmp_path):
    asf, amc = original
    reference = read(tmp_path, asf, amc)
    new_order = [3, 4, 5, 0, 1, 2]  # RX RY RZ TX TY TZ

    def reorder(match):
        words = match.group(2).split()
        return match.group(1) + b" ".join(words[i] for i in new_order)

    asf2 = asf.replace(b"order TX TY TZ RX RY RZ", b"order RX RY RZ TX TY TZ")
    amc2 = re.sub(rb"^(root )([^\r\n]*)", reorder, amc, flags=re.MULTILINE)
    motion = read(tmp_path, asf2, amc2)
    assert motion.skeleton.root.order == ("rx", "ry", "rz", "tx", "ty", "tz")
    assert motion.channels[0] == ("root", "rx")
    assert_same_motion(motion, reference)


def test_another_axis_order_with_angles_rewritten(original, tmp_path):
    """axis 0 0 20 XYZ written as the same frame in ZYX: read as written, the same rotation."""
    asf, amc = original

    def rewrite(match):
        angles = [float(x) for x in match.group(1).split()]
        zyx = Rotation.from_euler("xyz", angles, degrees=True).as_euler("zyx", degrees=True)
        return b"axis " + b" ".join(repr(float(a)).encode() for a in zyx[::-1]) + b" ZYX"

    asf2 = re.sub(rb"axis ([-\d.e+ ]+?)\s+XYZ", rewrite, asf)
    reference, motion = read(tmp_path, asf, amc), read(tmp_path, asf2, amc)
    for old, new in zip(reference.skeleton.bones, motion.skeleton.bones):
        assert new.axis_order == "ZYX"
        a = Rotation.from_euler("xyz", old.axis, degrees=True).as_matrix()
        b = Rotation.from_euler("zyx", new.axis[::-1], degrees=True).as_matrix()
        np.testing.assert_allclose(a, b, atol=1e-12)
    assert_same_motion(motion, reference)


def test_bones_shuffled_in_the_asf_and_in_every_frame(original, tmp_path, rng):
    asf, amc = original
    reference = read(tmp_path, asf, amc)
    head, rest = asf.split(b":bonedata", 1)
    blocks, tail = rest.split(b":hierarchy", 1)
    parts = re.findall(rb"\s*begin.*?end[^\r\n]*", blocks, flags=re.DOTALL)
    order = rng.permutation(len(parts))
    asf2 = head + b":bonedata" + b"".join(parts[i] for i in order) + b"\r\n:hierarchy" + tail
    frames = re.split(rb"(?m)^(?=\d+\s*$)", amc)
    shuffled = [frames[0]]
    for frame in frames[1:]:
        lines = frame.splitlines(keepends=True)
        body = lines[1:]
        shuffled.append(lines[0] + b"".join(body[i] for i in rng.permutation(len(body))))
    motion = read(tmp_path, asf2, b"".join(shuffled))
    assert set(motion.skeleton.bone_names) == set(reference.skeleton.bone_names)
    assert motion.skeleton.bone_names != reference.skeleton.bone_names
    assert_same_motion(motion, reference)


def test_hierarchy_lines_in_any_order(original, tmp_path):
    asf, amc = original
    head, tail = asf.split(b":hierarchy", 1)
    lines = tail.split(b"\r\n")
    inner = [i for i, line in enumerate(lines) if line.strip() and line.strip() not in (b"begin", b"end")]
    reordered = list(lines)
    for i, j in zip(inner, reversed(inner)):
        reordered[i] = lines[j]
    reference = read(tmp_path, asf, amc)
    motion = read(tmp_path, head + b":hierarchy" + b"\r\n".join(reordered), amc)
    assert motion.skeleton == reference.skeleton


def test_frames_numbered_from_any_start(original, tmp_path):
    asf, amc = original
    renumbered = re.sub(rb"(?m)^(\d+)(\s*)$", lambda m: str(int(m.group(1)) + 999).encode() + m.group(2), amc)
    motion = read(tmp_path, asf, renumbered)
    assert motion.first_frame == 1000
    mt.write_amc(motion, tmp_path / "out.amc")
    assert mt.read_amc(tmp_path / "out.amc", motion.skeleton).first_frame == 1000
