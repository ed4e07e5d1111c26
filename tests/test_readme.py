"""The README's examples run, as written, on the real files they name."""

import re
import shutil
from pathlib import Path

from conftest import SOURCE, needs_source

pytestmark = needs_source
README = SOURCE / "README.md"
FILES = ("cmu/01.asf", "cmu/01_01.amc", "cmu/02.asf", "cmu/02_01.amc", "cmu/02_02.amc", "bvh/walk01.bvh")


def blocks(language: str) -> list[str]:
    return re.findall(rf"```{language}\n(.*?)```", README.read_text(), flags=re.DOTALL)


def test_the_python_examples_run_in_order(data_dir, tmp_path, monkeypatch):
    for name in FILES:
        shutil.copy(data_dir / name, tmp_path / Path(name).name)
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    for n, code in enumerate(blocks("python"), start=1):
        try:
            exec(compile(code, f"README.md python block {n}", "exec"), namespace)  # noqa: S102 (running the docs is the point)
        except Exception as e:
            raise AssertionError(f"README python block {n} fails: {e!r}\n{code}") from e


def test_the_toml_examples_read(tmp_path):
    """Every TOML example reads: a recipe of steps through the registry, a retargeting map file
    ([joints]) through the map reader."""
    import motiontheater as mt
    from motiontheater.characters.rigs import read_map

    examples = blocks("toml")
    recipes = [text for text in examples if "[[step]]" in text]
    maps = [text for text in examples if text.lstrip().startswith("[joints]")]
    assert recipes and maps and len(recipes) + len(maps) == len(examples)
    for text in recipes:
        assert mt.Pipeline.from_toml(text, "README.md").entries
    for text in maps:
        (tmp_path / "map.toml").write_text(text)
        assert read_map(tmp_path / "map.toml")[0]
