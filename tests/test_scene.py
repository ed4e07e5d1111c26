"""Scenes, recipes and the combine command: the thesis tutorial on CMU takes."""

import numpy as np
import pytest

import motiontheater as mt
from motiontheater.cli import main

UPPER = [
    "lowerback",
    "upperback",
    "thorax",
    "lowerneck",
    "upperneck",
    "head",
    "lclavicle",
    "lhumerus",
    "lradius",
    "lwrist",
    "lhand",
    "lfingers",
    "lthumb",
    "rclavicle",
    "rhumerus",
    "rradius",
    "rwrist",
    "rhand",
    "rfingers",
    "rthumb",
]


@pytest.fixture
def recipe(data_dir, tmp_path):
    cmu = data_dir / "cmu"
    path = tmp_path / "tutorial.toml"
    path.write_text(f'''
skeleton = "{cmu / "02.asf"}"
[base]
motion = "{cmu / "02_01.amc"}"
[[track]]
motion = "{cmu / "02_02.amc"}"
joints = {UPPER}
cut = [1, 55]
scale = [1, 66]
[[track]]
motion = "{cmu / "02_01.amc"}"
joints = {UPPER}
cut = [67, 113]
blend = 10
''')
    return path


def test_thesis_tutorial(recipe, data_dir):
    """Legs from one take; upper body from another, cut 1..55 and scaled to 1..66; upper body again
    from the first take, cut 67..113 with blend depth 10."""
    skeleton = mt.read_asf(data_dir / "cmu" / "02.asf")
    first = mt.read_amc(data_dir / "cmu" / "02_01.amc", skeleton)
    second = mt.read_amc(data_dir / "cmu" / "02_02.amc", skeleton)
    result = mt.read_recipe(recipe).render()
    assert (result.first_frame, result.frames) == (1, 343)
    legs = [
        c
        for j in ("lfemur", "ltibia", "lfoot", "ltoes", "rfemur", "rtibia", "rfoot", "rtoes", "root")
        for c in result.columns(j)
    ]
    np.testing.assert_array_equal(result.values[:, legs], first.values[:, legs])
    upper = [c for j in UPPER for c in result.columns(j)]
    # frames 1..56 hold the second take's 1..55 stretched (frame 1 -> 1, frame 66 -> 55)
    np.testing.assert_array_equal(result.values[0, upper], second.values[0, upper])
    # inside the second track, clear of its blends, the first take again
    np.testing.assert_array_equal(result.values[77:102, upper], first.values[77:102, upper])
    # after the last blend (frame 123) everything is the first take
    np.testing.assert_array_equal(result.values[123:], first.values[123:])


def test_scene_api_equals_recipe(recipe, data_dir):
    skeleton = mt.read_asf(data_dir / "cmu" / "02.asf")
    first = mt.read_amc(data_dir / "cmu" / "02_01.amc", skeleton)
    second = mt.read_amc(data_dir / "cmu" / "02_02.amc", skeleton)
    scene = (
        mt.Scene(first)
        .add(second, joints=UPPER, cut=(1, 55), scale=(1, 66))
        .add(first, joints=UPPER, cut=(67, 113), blend=10)
    )
    assert len(scene.tracks) == 2 and scene.tracks[0].motion is second
    assert scene.render().values.tobytes() == mt.read_recipe(recipe).render().values.tobytes()
    with pytest.raises(ValueError, match="unknown track option"):
        scene.add(first, speed=2)


def test_combine_command(recipe, tmp_path, capsys):
    out = tmp_path / "out.amc"
    assert main(["combine", str(recipe), "-o", str(out)]) == 0
    assert capsys.readouterr().out.strip() == f"2 track(s) over 343 frames: wrote 343 frames (1..343) to {out}"
    assert mt.read_amc(out, mt.read_recipe(recipe).base.skeleton).values.tobytes() == (
        mt.read_recipe(recipe).render().values.tobytes()
    )


def test_dry_run_prints_the_frame_maps(recipe, tmp_path, capsys):
    assert main(["combine", str(recipe), "--dry-run"]) == 0
    out = capsys.readouterr().out
    assert "piece 1..66 from source frames 1..55" in out
    assert "start border at 67: blend 57..77 (depth 10 + 10, step 1/22)" in out
    assert list(tmp_path.iterdir()) == [recipe]


def test_bad_recipes(tmp_path, capsys, data_dir):
    bad = tmp_path / "bad.toml"
    bad.write_text(
        f'[base]\nmotion = "{data_dir / "cmu" / "02_01.amc"}"\n[[track]]\nmotion = "{data_dir / "cmu" / "02_02.amc"}"\ncut = [0, 999]\n'
    )
    assert main(["combine", str(bad), "-o", str(tmp_path / "o.amc")]) == 2
    err = capsys.readouterr().err
    assert (
        err.startswith("motiontheater combine: track 1 (")
        and "02_02.amc): cut=(0, 999) is outside the new motion's frames 1..298" in err
    )
    bad.write_text("this is = = not toml")
    assert main(["combine", str(bad), "--dry-run"]) == 2
    assert "not a valid TOML recipe" in capsys.readouterr().err
    bad.write_text("[[track]]\nmotion = 'a.amc'\n")
    assert main(["combine", str(bad), "--dry-run"]) == 2
    assert "the recipe needs [base]" in capsys.readouterr().err
    assert not (tmp_path / "o.amc").exists()


def test_a_track_is_planned_once(data_dir):
    """Each track's warnings come once per render, not once more for a second planning."""
    take = mt.read_amc(data_dir / "cmu" / "02_01.amc", mt.read_asf(data_dir / "cmu" / "02.asf"))
    with pytest.warns(UserWarning, match="blend and preserve exclude each other") as caught:
        mt.Scene(take).add(take, blend=5, preserve="literal").render()
    assert len(caught) == 1


def test_combine_keeps_another_skeleton_beside_its_output_unless_in_place(recipe, tmp_path, capsys, data_dir):
    out = tmp_path / "out.amc"
    other = (data_dir / "cmu" / "01.asf").read_bytes()  # another subject's skeleton, where out.asf goes
    (tmp_path / "out.asf").write_bytes(other)
    assert main(["combine", str(recipe), "-o", str(out)]) == 2
    assert "out.asf exists and holds another skeleton" in capsys.readouterr().err
    assert not out.exists() and (tmp_path / "out.asf").read_bytes() == other
    assert main(["combine", str(recipe), "-o", str(out), "--in-place"]) == 0
    assert (tmp_path / "out.asf").read_bytes() != other
