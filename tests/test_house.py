"""The house rules: imports flow one way, the cffi stub matches the header, a step is registered once
and reached from everywhere."""

import ast
import subprocess
import sys
from pathlib import Path
from typing import Annotated

import numpy as np
import pytest

import motiontheater as mt
from conftest import SOURCE, needs_source
from motiontheater import registry
from motiontheater.cli import build_parser, main

PACKAGE = SOURCE / "python" / "motiontheater"


def imports_of(path: Path) -> set[str]:
    """The package's modules that ``path`` imports, anywhere in it (functions included)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.level == 1:
            if node.module:
                found.add(node.module.split(".")[0])
            else:  # from . import x: a submodule when there is one, else the package root
                found |= {a.name if (PACKAGE / f"{a.name}.py").exists() else "__init__" for a in node.names}
        elif isinstance(node, ast.ImportFrom) and (node.module or "").startswith("motiontheater"):
            found.add((node.module or "").split(".")[1] if "." in (node.module or "") else "__init__")
        elif isinstance(node, ast.Import):
            found |= {a.name.split(".")[1] for a in node.names if a.name.startswith("motiontheater.")}
            found |= {"__init__" for a in node.names if a.name == "motiontheater"}
    return found


@needs_source
def test_imports_flow_one_way():
    graph = {p.stem: imports_of(p) for p in PACKAGE.glob("*.py")}
    for module, imported in graph.items():
        assert module == "__init__" or "__init__" not in imported, f"{module} imports the package root"
    order, done = [], set()

    def visit(module, path):
        if module in path:
            raise AssertionError("import cycle: " + " -> ".join([*path, module]))
        if module not in done:
            for child in sorted(graph.get(module, ())):
                visit(child, [*path, module])
            done.add(module)
            order.append(module)

    for module in sorted(graph):
        visit(module, [])
    assert order.index("registry") < order.index("motion") < order.index("filtering")


@needs_source
def test_the_cffi_stub_is_generated_from_the_header(tmp_path):
    subprocess.run(
        [
            sys.executable,
            str(SOURCE / "src" / "cffi_build.py"),
            "--stub",
            str(SOURCE / "csrc" / "mtcore.h"),
            str(tmp_path / "stub.pyi"),
        ],
        check=True,
    )
    committed = (SOURCE / "src" / "mtcore" / "_mtcore.pyi").read_text()
    assert (tmp_path / "stub.pyi").read_text() == committed, (
        "src/mtcore/_mtcore.pyi is stale: python src/cffi_build.py --stub csrc/mtcore.h src/mtcore/_mtcore.pyi"
    )


@pytest.fixture
def toy():
    """A step registered by a test, as a new capability would be: found everywhere, then forgotten."""

    @registry.step("toy_offset", "add a constant to chosen channels (a test's step)")
    def toy_offset(
        motion: mt.Motion,
        *,
        amount: Annotated[float, "what to add"],
        joints: Annotated[registry.Joints, "joints to change (default: all)"] = None,
    ) -> mt.Motion:
        columns = [c for j in (joints or motion.skeleton.joint_names) for c in motion.columns(j)]
        values = motion.values.copy()
        values[:, columns] += amount
        return motion.replace(values=values)

    yield toy_offset
    registry.unregister("toy_offset")


def test_a_registered_step_is_a_method_a_pipeline_step_a_verb_a_recipe_and_a_batch_step(
    toy, data_dir, tmp_path, capsys
):
    motion = mt.read_bvh(data_dir / "bvh" / "walk01.bvh")
    expected = toy(motion, amount=2.5, joints=("Hips",))
    # a method
    np.testing.assert_array_equal(motion.toy_offset(amount=2.5, joints=("Hips",)).values, expected.values)
    np.testing.assert_array_equal(motion.apply("toy_offset", amount=2.5, joints=("Hips",)).values, expected.values)
    # a pipeline step, over a range of frames too
    pipeline = mt.Pipeline().then("toy_offset", amount=2.5, joints=["Hips"], frames=(3, 5))
    ranged = pipeline.apply(motion)
    np.testing.assert_array_equal(ranged.values[2:5], expected.values[2:5])
    np.testing.assert_array_equal(ranged.values[5:], motion.values[5:])
    # a verb, with its --help
    assert "toy_offset" in build_parser().format_help()
    with pytest.raises(SystemExit):
        main(["toy_offset", "--help"])
    assert "--amount X" in capsys.readouterr().out
    out = tmp_path / "one.bvh"
    assert main(["toy_offset", str(data_dir / "bvh" / "walk01.bvh"), "-o", str(out), "--amount", "2.5"]) == 0
    np.testing.assert_array_equal(mt.read_bvh(out).values, toy(motion, amount=2.5).values)
    # a recipe entry, applied by the CLI and by batch
    recipe = tmp_path / "steps.toml"
    recipe.write_text('[[step]]\nrun = "toy_offset"\namount = 2.5\njoints = ["Hips"]\n')
    assert mt.Pipeline.read(recipe) == mt.Pipeline.of("toy_offset", amount=2.5, joints=("Hips",))
    assert main(["apply", str(data_dir / "bvh" / "walk01.bvh"), "--recipe", str(recipe), "-o", str(out)]) == 0
    np.testing.assert_array_equal(mt.read_bvh(out).values, expected.values)
    folder = tmp_path / "batch"
    assert main(["batch", "--recipe", str(recipe), str(data_dir / "bvh" / "walk01.bvh"), "-o", str(folder)]) == 0
    np.testing.assert_array_equal(mt.read_bvh(folder / "walk01.bvh").values, expected.values)
    # and listed
    capsys.readouterr()
    assert main(["steps"]) == 0
    assert "toy_offset: add a constant to chosen channels" in capsys.readouterr().out


def test_steps_refuse_what_they_do_not_take(toy, data_dir):
    motion = mt.read_bvh(data_dir / "bvh" / "walk01.bvh")
    with pytest.raises(mt.StepError, match="step 'toy_offset' needs the option 'amount'"):
        motion.toy_offset()
    with pytest.raises(mt.StepError, match="step 'toy_offset' has no option 'size'"):
        motion.toy_offset(amount=1, size=3)
    with pytest.raises(mt.StepError, match="step 'toy_offset': amount must be a number, got 'x'"):
        mt.Pipeline().then("toy_offset", amount="x")
    with pytest.raises(mt.StepError, match="step 'toy_offset': frames: the first frame 9 comes after the last 3"):
        motion.toy_offset(amount=1, frames=(9, 3))
    with pytest.raises(AttributeError, match="no attribute 'toy_offse'"):
        motion.toy_offse(amount=1)
    with pytest.raises(ValueError, match="a step 'toy_offset' is registered already"):
        registry.register("toy_offset", toy)
    with pytest.raises(mt.StepError, match=r"recipe.toml: step 1: no step 'nothing'"):
        mt.Pipeline.from_toml('[[step]]\nrun = "nothing"\n', "recipe.toml")
