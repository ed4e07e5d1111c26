"""The command line of retargeting, and the registry's hook for a step's dry run."""

from typing import Annotated

import pytest

import motiontheater as mt
from motiontheater import registry
from motiontheater.cli import main


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
