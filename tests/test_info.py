"""motiontheater info: what a take holds, in words and in JSON, for every real file."""

import io
import json

import numpy as np
import pytest

import motiontheater as mt
from corpus import ids, real_files
from motiontheater.cli import main
from motiontheater.cli.info import as_text, describe
from variants import with_offset_channels, with_static_root

TAKES = real_files("*/*.bvh") + real_files("*/*.amc")


def info_json(capsys, *args):
    assert main(["info", *map(str, args), "--json"]) == 0
    return json.loads(capsys.readouterr().out)


@pytest.mark.parametrize("take", TAKES, ids=ids(TAKES))
def test_info_on_every_real_take(take, capsys):
    assert main(["info", str(take)]) == 0
    text = " ".join(capsys.readouterr().out.split())  # unwrapped
    facts = info_json(capsys, take)
    motion = mt.read_take(take)
    assert facts["frames"] == motion.frames and facts["first_frame"] == motion.first_frame
    assert facts["frame_rate"] == motion.frame_rate
    assert facts["duration"] == pytest.approx(motion.frames / motion.frame_rate)
    assert facts["length_unit"]["source"] == motion.skeleton.length_source
    assert facts["length_unit"]["meters_per_unit"] == motion.skeleton.meters_per_unit
    channels = [c for j in facts["joints"] for c in j["channels"]]
    assert [c["column"] for c in channels] == list(range(len(motion.skeleton.channels)))
    np.testing.assert_array_equal([c["min"] for c in channels], motion.values.min(axis=0))
    np.testing.assert_array_equal([c["max"] for c in channels], motion.values.max(axis=0))
    rest = facts["rest_pose"]
    assert rest["height_m"] == pytest.approx(rest["height"] * motion.skeleton.meters_per_unit)
    for words in ("frames", "length unit", "up axis", "height", "Joint tree", "--unit UNIT"):
        assert words in text
    frames = f"{motion.frames} frame{'s' if motion.frames > 1 else ''}"
    assert f"{frames}, numbered {motion.first_frame} to {motion.last_frame}" in text
    assert facts["length_unit"]["source"] in text
    for joint in facts["joints"]:
        assert joint["name"] in text


def test_info_of_a_bvh(data_dir, capsys):
    facts = info_json(capsys, data_dir / "bvh" / "walk01.bvh")
    assert facts["format"] == "BVH" and facts["skeleton_file"] is None
    assert (facts["frames"], facts["first_frame"], facts["last_frame"]) == (101, 1, 101)
    assert facts["length_unit"]["label"] == "cm" and facts["length_unit"]["source"] == "detected"
    assert "185.4 units tall along y" in facts["length_unit"]["why"]
    assert facts["up_axis"] == "y" and facts["rest_pose"]["height_m"] == pytest.approx(1.854, abs=1e-3)
    assert 1.2 < facts["first_frame_height_m"] < 2.2
    hips, up_leg = facts["joints"][:2]
    assert (hips["name"], hips["kind"], hips["parent"], hips["depth"]) == ("Hips", "root", None, 0)
    assert [c["name"] for c in hips["channels"]] == ["Xposition", "Yposition", "Zposition"] + [
        "Zrotation",
        "Xrotation",
        "Yrotation",
    ]
    assert hips["channels"][0]["unit"] == "cm" and hips["channels"][3]["unit"] == "deg"
    assert (up_leg["parent"], up_leg["depth"], up_leg["kind"]) == ("Hips", 1, "joint")
    assert facts["joints"][4] == {
        "name": "RightFoot_End",
        "parent": "RightFoot",
        "kind": "end site",
        "depth": 4,
        "channels": [],
    }


def test_info_says_why_cmus_conversion_is_in_its_asf_unit(data_dir, capsys):
    assert main(["info", str(data_dir / "cmu" / "01_01.bvh")]) == 0
    text = " ".join(capsys.readouterr().out.split())  # unwrapped
    assert "in/0.45 = 0.05644 m, detected: its rest pose stands 25.65 units tall along y, 1.448 m" in text
    assert "in CMU's inch/0.45: its joints are named as in CMU's BVH conversion (LHipJoint, RHipJoint)" in text


@pytest.mark.parametrize("name", ["sinusoidal.bvh"])
def test_info_says_a_unit_was_assumed_and_how_to_set_it(data_dir, name, capsys):
    path = next(data_dir.glob(f"*/{name}"))
    assert main(["info", str(path)]) == 0
    text = " ".join(capsys.readouterr().out.split())  # unwrapped
    assert "cm = 0.01 m, assumed: no unit of mm, cm, in, m makes the rest pose" in text
    assert "Set another with --unit UNIT (Python: unit=UNIT)" in text
    if name != "sinusoidal.bvh":  # CMU's naming: the hint of its real unit
        assert "whose unit is the CMU ASF's inch/0.45: if it is one, --unit 0.45" in text
    else:
        assert "CMU's BVH conversion" not in text
    facts = info_json(capsys, path, "--unit", "0.45")
    assert facts["length_unit"]["source"] == "given" and facts["length_unit"]["label"] == "in/0.45"


def test_info_of_an_amc(data_dir, capsys):
    amc = data_dir / "cmu" / "02_01.amc"
    facts = info_json(capsys, amc)
    assert facts["format"] == "ASF/AMC" and facts["skeleton_file"] == str(data_dir / "cmu" / "02.asf")
    assert facts["length_unit"]["text"] == "0.45" and facts["length_unit"]["source"] == "stated"
    assert facts["frame_rate"] == 120 and facts["frame_rate_source"] == "assumed"
    assert facts["joints"][0]["name"] == "root" and facts["joints"][0]["channels"][0]["unit"] == "in/0.45"
    given = info_json(capsys, amc, "--frame-rate", "60", "--asf", data_dir / "cmu" / "02.asf")
    assert given["frame_rate"] == 60 and given["frame_rate_source"] == "given"
    assert main(["info", str(data_dir / "edge" / "test.amc")]) == 0
    text = " ".join(capsys.readouterr().out.split())
    assert "mm = 0.001 m, detected: the skeleton states :units length m, which makes it 1582 m in size" in text


def test_info_of_no_frames_and_of_nan():
    bvh = TINY.replace("Frames: 2", "Frames: 0").split("Frame Time: 0.5\n")[0] + "Frame Time: 0.5\n"
    empty = mt.read_bvh(io.BytesIO(bvh.encode()))
    facts = describe(empty)
    assert facts["frames"] == 0 and facts["last_frame"] == 0 and facts["first_frame_height"] is None
    assert facts["joints"][0]["channels"][0]["min"] is None
    assert "no frames (the first would be number 1)" in as_text(facts)
    motion = mt.read_bvh(io.BytesIO(TINY.encode()))
    values = motion.values.copy()
    values[:, 4] = np.nan  # a channel without a number
    values[0, 5] = np.nan  # and a gap in another
    facts = describe(motion.replace(values=values))
    json.dumps(facts, allow_nan=False)  # NaN never reaches JSON
    channels = facts["joints"][0]["channels"]
    assert channels[4]["min"] is None and channels[5]["min"] == channels[5]["max"] == 7.0


def test_info_fails_cleanly(tmp_path, capsys):
    assert main(["info", str(tmp_path / "none.bvh")]) == 2
    assert capsys.readouterr().err.strip() == f"motiontheater info: {tmp_path / 'none.bvh'}: no such file"
    (tmp_path / "bad.bvh").write_text("HIERARCHY\nROOT a\n{\n")
    assert main(["info", str(tmp_path / "bad.bvh")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("motiontheater info: ") and "bad.bvh" in err and len(err.strip().splitlines()) == 1


TINY = """HIERARCHY
ROOT Hips
{
\tOFFSET 0 0 0
\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
\tJOINT Head
\t{
\t\tOFFSET 0 10 0
\t\tCHANNELS 3 Zrotation Xrotation Yrotation
\t\tEnd Site
\t\t{
\t\t\tOFFSET 0 5 0
\t\t}
\t}
}
MOTION
Frames: 2
Frame Time: 0.5
1 2 3 4 5 6 7 8 9
1 2 3 4 5 7 7 8 9
"""


def test_every_verb_that_reads_takes_takes_a_unit():
    from motiontheater.cli import build_parser

    verbs = build_parser()._subparsers._group_actions[0].choices
    readers = {name for name, p in verbs.items() if any(a.dest == "asf" for a in p._actions)}
    assert {"info", "filter", "apply", "batch", "convert", "positions", "median"} <= readers
    # bench reads a take for its timings only; index and search measure bodies in leg lengths,
    # which no length unit changes (test_cli_units would refuse a --unit that changes nothing)
    for name in readers - {"bench", "index", "search"}:
        assert any(a.dest == "unit" for a in verbs[name]._actions), name


def test_batch_reads_with_the_unit_given(data_dir, tmp_path):
    (tmp_path / "in").mkdir()
    (tmp_path / "in" / "walk01.bvh").write_bytes((data_dir / "bvh" / "walk01.bvh").read_bytes())
    (tmp_path / "r.toml").write_text('[[step]]\nrun = "positions"\n')
    args = ["batch", str(tmp_path / "in"), "-o", str(tmp_path / "out"), "--recipe", str(tmp_path / "r.toml")]
    assert main([*args, "--jobs", "1", "--quiet", "--unit", "mm"]) == 0
    assert (tmp_path / "out" / "walk01.csv").read_text().split(",")[2] == "Hips.x [mm]"


def test_a_game_rig_names_its_body_its_static_root_and_its_offset_channels(data_dir, tmp_path):
    take = mt.read_bvh(data_dir / "bvh" / "walk01.bvh")
    game = with_static_root(with_offset_channels(take), turn=(90.0, 0.0, 0.0), keep_world=False)
    path = tmp_path / "game.bvh"
    mt.write_bvh(game, path)
    facts = describe(mt.read_bvh(path), path)
    moving = [j for j in take.skeleton.bone_names if take.skeleton.dofs(j) and not take.skeleton.bone(j).end_site]
    assert facts["body"] == {
        "joint": "Hips",
        "why": "the first joint in the file whose position channels move; the joints above it stand still (Reference)",
        "static_joints": ["Reference"],
        "offset_channels": 3 * len(moving),
        "offset_joints": len(moving),
    }
    assert facts["up_axis"] == "z" and "hips are above the ankles" in facts["up_reason"]
    text = as_text(facts)
    assert "body         Hips: the first joint" in text and "only hold their OFFSET" in text


def test_a_chain_of_ten_thousand_joints_is_described_in_lines_a_person_can_read(tmp_path):
    """Depths in one walk, the cycle check in one walk, indentation capped: a 10,000-level chain
    took 17 s and printed lines of 20,000 spaces."""
    n = 10_000
    lines = [
        "HIERARCHY",
        "ROOT r",
        "{",
        "OFFSET 0 0 0",
        "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation",
    ]
    for i in range(n):
        lines += [f"JOINT j{i}", "{", "OFFSET 0 1 0", "CHANNELS 3 Zrotation Xrotation Yrotation"]
    lines += ["End Site", "{", "OFFSET 0 1 0", "}"] + ["}"] * (n + 1)
    lines += ["MOTION", "Frames: 1", "Frame Time: 0.04", " ".join(["0"] * (6 + 3 * n))]
    path = tmp_path / "deep.bvh"
    path.write_text("\n".join(lines) + "\n")
    facts = describe(mt.read_bvh(path), path)
    assert [j["depth"] for j in facts["joints"]][-3:] == [n - 1, n, n + 1]
    text = as_text(facts)
    assert max(len(line) for line in text.splitlines()) < 200
    assert "[10001] j9999_End (end site)" in text
