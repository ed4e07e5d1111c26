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
from motiontheater.cli import build_parser, main
from motiontheater.model import registry

pytestmark = needs_source  # the house rules are about the checkout's own files
ROOT = SOURCE
PACKAGES = {"motiontheater": ROOT / "python" / "motiontheater", "mtcore": ROOT / "src" / "mtcore"}
# The mocap floor's groups, bottom up (ARCHITECTURE.md): a module imports from its own group and
# the ones below it, never from one above.  The package's private plumbing (_io, _version,
# _optional) is the ground floor; the package root and __main__ stand on top.
GROUPS = ["", "model", "formats", "editing", "feet", "characters", "views", "databases", "cli"]


def modules(package: str) -> dict[str, Path]:
    """Every module of a package by dotted name (a folder's __init__ named as the folder)."""
    folder = PACKAGES[package]
    found = {}
    for path in folder.rglob("*.py"):
        parts = [package, *path.relative_to(folder).with_suffix("").parts]
        found[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return found


def imports_of(name: str, path: Path, known: dict[str, Path]) -> set[str]:
    """The modules of ``known`` that module ``name`` (at ``path``) imports, anywhere in it."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()

    def add(target: str, names=()):
        submodules = {f"{target}.{alias}" for alias in names} & known.keys()  # from package import module
        found.update(submodules)
        if target in known and (len(submodules) < len(names) or not names):
            found.add(target)

    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - node.level + 1]
                target = ".".join([*base, *([node.module] if node.module else [])])
            else:
                target = node.module or ""
            add(target, [a.name for a in node.names])
        elif isinstance(node, ast.Import):
            for alias in node.names:
                add(alias.name)
    return found


def group_of(name: str) -> int:
    parts = name.split(".")
    if len(parts) == 1 or parts[1] == "__main__":
        return len(GROUPS)  # the package root and __main__
    return GROUPS.index(parts[1]) if parts[1] in GROUPS else 0


def import_graph() -> dict[str, set[str]]:
    known = {**modules("motiontheater"), **modules("mtcore")}
    return {name: imports_of(name, path, known) for name, path in known.items()}


def test_imports_flow_one_way():
    graph = import_graph()
    for module, imported in graph.items():
        root = module.split(".")[0]
        assert module == root or root not in imported, f"{module} imports the package root {root}"
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
    assert order.index("motiontheater.model.registry") < order.index("motiontheater.model.motion")
    assert order.index("motiontheater.model.motion") < order.index("motiontheater.editing.filtering")


def test_no_group_imports_one_above_it():
    graph = import_graph()
    upward = [
        f"{module} ({GROUPS[group_of(module)] or 'ground'}) imports {target} ({GROUPS[group_of(target)]})"
        for module, imported in graph.items()
        if module.startswith("motiontheater.")
        for target in imported
        if target.startswith("motiontheater.") and group_of(target) > group_of(module)
    ]
    assert not upward, "\n".join(upward)


def test_every_module_lives_in_a_group():
    strays = [
        name
        for name in modules("motiontheater")
        if name.count(".") == 1 and name.split(".")[1] not in GROUPS and not name.split(".")[1].startswith("_")
    ]
    assert not strays, f"modules outside the groups of ARCHITECTURE.md: {strays}"


def cffi_uses(path: Path) -> list[str]:
    """Where a module reaches the cffi module: imports of _mtcore, and attributes named lib or ffi."""
    tree = ast.parse(path.read_text())
    uses = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and (
            "_mtcore" in (node.module or "") or any(a.name in ("lib", "ffi", "_mtcore") for a in node.names)
        ):
            uses.append(f"line {node.lineno}: from {node.module} import ...")
        elif isinstance(node, ast.Import) and any("_mtcore" in a.name for a in node.names):
            uses.append(f"line {node.lineno}: import _mtcore")
        elif isinstance(node, ast.Attribute) and node.attr in ("lib", "ffi", "_mtcore"):
            uses.append(f"line {node.lineno}: .{node.attr}")
    return uses


def test_only_mtcore_calls_the_c_core():
    found = {name: cffi_uses(path) for name, path in modules("motiontheater").items()}
    found = {name: uses for name, uses in found.items() if uses}
    assert not found, f"the mocap floor reaches the cffi module directly (call an mtcore function): {found}"


def test_the_house_test_sees_a_use_of_lib(tmp_path):
    bad = tmp_path / "bad.py"
    bad.write_text("import mtcore\n\ndef f():\n    return mtcore.filters.lib.mt_filter1d_block(5)\n")
    assert cffi_uses(bad) == ["line 4: .lib"]


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
    with pytest.warns(
        DeprecationWarning, match=r"motion.apply\('toy_offset', ...\) is deprecated: write motion.toy_offset\(...\)"
    ):
        np.testing.assert_array_equal(motion.apply("toy_offset", amount=2.5, joints=("Hips",)).values, expected.values)
    with pytest.warns(
        DeprecationWarning, match=r"motion.filter\('median', 3, ...\) is deprecated: write motion.median\(size=3, ...\)"
    ):
        np.testing.assert_array_equal(motion.filter("median", 3).values, motion.median(size=3).values)
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
