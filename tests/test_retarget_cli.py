"""The command line of retargeting, and the registry's hook for a step's dry run."""

from typing import Annotated

import numpy as np
import pytest

import motiontheater as mt
from motiontheater.characters.retarget import read_target
from motiontheater.cli import main
from motiontheater.model import registry


@pytest.fixture
def toy():
    """A step with a dry run, registered by a test and then forgotten."""

    def explain(motion: mt.Motion, *, amount: float, frames: tuple[int, int] | None) -> str:
        first, last = frames or (motion.first_frame, motion.last_frame)
        return f"would add {amount} to frames {first}..{last}"

    @registry.step("toy_shift", "add a constant to every channel (a test's step)", dry_run=explain)
    def toy_shift(motion: mt.Motion, *, amount: Annotated[float, "what to add"]) -> mt.Motion:
        return motion.replace(values=motion.values + amount)

    yield toy_shift
    registry.unregister("toy_shift")


def test_a_step_with_a_dry_run_gets_the_flag_and_writes_nothing(toy, data_dir, tmp_path, capsys):
    walk = data_dir / "bvh" / "walk01.bvh"
    out = tmp_path / "out.bvh"
    assert main(["toy_shift", str(walk), "--amount", "2", "--dry-run"]) == 0  # no output needed
    assert capsys.readouterr().out.strip() == "would add 2.0 to frames 1..101"
    assert main(["toy_shift", str(walk), "-o", str(out), "--amount", "2", "--dry-run"]) == 0
    assert not out.exists()
    step = registry.lookup("toy_shift")
    assert step.describe(mt.read_bvh(walk), amount=3, frames=(5, 9)) == "would add 3.0 to frames 5..9"
    with pytest.raises(mt.StepError, match="needs the option 'amount'"):
        step.describe(mt.read_bvh(walk))
    with pytest.raises(mt.StepError, match="step 'median' has no dry run"):
        registry.lookup("median").describe(mt.read_bvh(walk), size=3)
    with pytest.raises(SystemExit):
        main(["median", str(walk), "--size", "3", "--dry-run"])  # steps without one have no such flag
    assert "unrecognized arguments: --dry-run" in capsys.readouterr().err


def retarget_api(data_dir, take: str, target: str) -> mt.Motion:
    motion = mt.read_take(data_dir / take)
    return mt.retarget(motion, read_target(data_dir / target), cleanup=False)


def test_retarget_writes_the_targets_format(data_dir, tmp_path, capsys):
    out = tmp_path / "walk.bvh"
    args = ["retarget", str(data_dir / "cmu" / "01_01.amc"), "--to", str(data_dir / "bvh" / "walk01.bvh")]
    assert main([*args, "-o", str(out), "--no-cleanup"]) == 0
    assert "2751 frames" in capsys.readouterr().out
    expected = retarget_api(data_dir, "cmu/01_01.amc", "bvh/walk01.bvh")
    np.testing.assert_array_equal(mt.read_bvh(out).values, expected.values)
    # an ASF target: the take as AMC and the target's skeleton beside it
    amc = tmp_path / "two.amc"
    args = ["retarget", str(data_dir / "bvh" / "walk01.bvh"), "--to", str(data_dir / "cmu" / "02.asf")]
    assert main([*args, "-o", str(amc), "--no-cleanup"]) == 0
    assert "two.asf" in capsys.readouterr().out
    back = mt.read_amc(amc, mt.read_asf(tmp_path / "two.asf"))
    expected = retarget_api(data_dir, "bvh/walk01.bvh", "cmu/02.asf")
    np.testing.assert_allclose(back.values, expected.values, rtol=0, atol=1e-12)
    assert back.skeleton.bones == expected.skeleton.bones


def test_dry_run_prints_the_plan_and_writes_nothing(data_dir, tmp_path, capsys):
    out = tmp_path / "walk.bvh"
    args = ["retarget", str(data_dir / "cmu" / "01_01.amc"), "--to", str(data_dir / "bvh" / "walk01.bvh")]
    assert main([*args, "-o", str(out), "--dry-run"]) == 0
    text = capsys.readouterr().out
    assert not out.exists()
    for expected in (
        "joint map (19 pairs, source -> target):",
        "lfemur    -> LeftUpLeg",
        "unmapped source joints (10): ltoes, rtoes, upperback",
        "unmapped target joints: none",
        "mode: directions",
        "units: source in/0.45 = 0.0564444 m (stated by its ASF); target cm = 0.01 m (detected from its size)",
        "scale factors: legs x",
        "up axes: source +y, target +y",
        "cleanup: ",
    ):
        assert expected in text, expected


@pytest.mark.parametrize(
    ("target", "map_text", "message"),
    [
        ("bvh/sinusoidal.bvh", None, "no joints in common"),
        ("lying.bvh", None, "the target skeleton 'lying' does not stand in its rest pose"),
        ("bvh/walk01.bvh", '[joints]\nlfemurr = "LeftUpLeg"\n', "map.toml: 'lfemurr' is not a joint of the source"),
        ("bvh/walk01.bvh", '[joints]\nlfemur = "Nowhere"\n', "map.toml: 'Nowhere' is not a joint of the target"),
        ("furlong.asf", None, "unknown length unit 'furlong'"),
        ("missing.bvh", None, "missing.bvh: no such target skeleton file"),
        ("cmu/01_01.amc", None, "the target must be a skeleton file (.asf or .bvh)"),
        ("small.bvh", None, "the target skeleton 'small' has no known length unit"),
    ],
)
def test_bad_input_is_one_line_and_writes_nothing(data_dir, tmp_path, capsys, target, map_text, message):
    if target == "furlong.asf":
        text = (data_dir / "cmu" / "02.asf").read_text().replace("length 0.45", "length furlong")
        (tmp_path / target).write_text(text)
        target_path = tmp_path / target
    elif target == "small.bvh":  # CMU's conversion, named otherwise: 26 units tall, no unit told
        text = (data_dir / "cmu" / "01_01.bvh").read_bytes().replace(b"HipJoint", b"Hip_")
        target_path = tmp_path / target
        target_path.write_bytes(text)
    elif target == "lying.bvh":  # jesse_dance's rig, every bone along x at rest, and no frame that stands
        text = (data_dir / "bvh" / "jesse_dance.bvh").read_bytes().split(b"MOTION")[0]
        target_path = tmp_path / target
        target_path.write_bytes(text + b"MOTION\nFrames: 0\nFrame Time: 0.0333333\n")
    else:
        target_path = data_dir / target if target != "missing.bvh" else tmp_path / target
    args = ["retarget", str(data_dir / "cmu" / "01_01.amc"), "--to", str(target_path), "-o", str(tmp_path / "o.bvh")]
    if map_text is not None:
        (tmp_path / "map.toml").write_text(map_text)
        args += ["--map", str(tmp_path / "map.toml")]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1, err
    assert not (tmp_path / "o.bvh").exists()


def test_the_targets_unit_can_be_given(data_dir, capsys):
    args = ["retarget", str(data_dir / "cmu" / "01_01.amc"), "--to", str(data_dir / "cmu" / "01_01.bvh"), "--dry-run"]
    assert main([*args, "--to-unit", "0.45"]) == 0
    assert "target in/0.45 = 0.0564444 m (given)" in capsys.readouterr().out
    assert main([*args, "--to-unit", "furlong"]) == 2
    assert "unknown length unit 'furlong'" in capsys.readouterr().err


def test_an_output_of_the_other_format_is_refused(data_dir, tmp_path, capsys):
    args = ["retarget", str(data_dir / "cmu" / "01_01.amc"), "--to", str(data_dir / "bvh" / "walk01.bvh")]
    assert main([*args, "-o", str(tmp_path / "walk.amc"), "--no-cleanup"]) == 2
    assert "name the output .bvh" in capsys.readouterr().err
    assert not list(tmp_path.iterdir())


def test_retarget_in_a_recipe_and_in_batch(data_dir, tmp_path):
    recipe = tmp_path / "steps.toml"
    target = tmp_path / "targets" / "02.asf"
    target.parent.mkdir()
    target.write_bytes((data_dir / "cmu" / "02.asf").read_bytes())
    recipe.write_text('[[step]]\nrun = "retarget"\nto = "targets/02.asf"\ncleanup = false\n')  # relative to the recipe
    pipeline = mt.Pipeline.read(recipe)
    motion = mt.read_take(data_dir / "cmu" / "01_01.amc")
    expected = mt.retarget(motion, mt.read_asf(target), cleanup=False)
    np.testing.assert_array_equal(pipeline.apply(motion).values, expected.values)
    folder = tmp_path / "out"
    assert main(["batch", "--recipe", str(recipe), str(data_dir / "cmu" / "01_01.amc"), "-o", str(folder)]) == 0
    written = mt.read_amc(folder / "01_01.amc", mt.read_asf(folder / "01_01.asf"))
    np.testing.assert_allclose(written.values, expected.values, rtol=0, atol=1e-12)
