"""--help that teaches: every ``Example:`` line of every verb's help runs as pasted in a folder holding
the takes it names (and the recipes the help shows), no help shows docstring markup, and ``steps``
lists options as a recipe writes them."""

import argparse
import os
import re
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from corpus import DATA
from motiontheater.cli import build_parser, main
from motiontheater.editing.pipeline import Pipeline
from motiontheater.formats.amc import skeleton_path_for

try:
    import tomllib
except ImportError:  # Python 3.10
    import tomli as tomllib


def verb_helps() -> dict[str, str]:
    """Each verb's --help text, by name (not by alias)."""
    subparsers = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    return {name: p.format_help() for name, p in subparsers.choices.items() if p.prog == f"motiontheater {name}"}


HELPS = verb_helps()
EXAMPLES = [
    (verb, line.removeprefix("Example: "))
    for verb, text in HELPS.items()
    for line in text.splitlines()
    if line.startswith("Example: ")
]
TAKE_NAME = re.compile(r"[\w.-]+\.(?:amc|asf|bvh)\b")
USER_FOLDER = ("01_01.amc", "01.asf", "02_01.amc", "02.asf")  # a folder of captures an example names


def shown_file(help_text: str, name: str) -> str:
    """The file ``name`` as the help shows it: the indented block after a line ending in 'NAME:'."""
    found = re.search(rf"{re.escape(name)}:\n\n((?:  .*\n|\n)+)", help_text)
    assert found, f"the help names {name} but does not show what it holds (an indented block after '{name}:')"
    return textwrap.dedent(found.group(1))


def user_folder(verb: str, command: str, folder: Path) -> None:
    """The files the example names: takes from the corpus, recipes as the help shows them, folders of takes."""
    texts = [command]
    for recipe in re.findall(r"[\w.-]+\.toml\b", command):
        texts.append(shown_file(HELPS[verb], recipe))
        (folder / recipe).write_text(texts[-1])
    for name in {n for text in texts for n in TAKE_NAME.findall(text)}:
        if (DATA / "cmu" / name).is_file():
            shutil.copy(DATA / "cmu" / name, folder)
            if name.endswith(".amc"):  # and its skeleton, as a user has it beside
                shutil.copy(skeleton_path_for(DATA / "cmu" / name), folder)
    for name in re.findall(r"(?<!\S)([\w.-]+)/(?!\S)", command):
        if not (folder / name).exists() and f"-o {name}/" not in command:
            (folder / name).mkdir()
            for take in USER_FOLDER:
                shutil.copy(DATA / "cmu" / take, folder / name)


@pytest.fixture
def shell_env(tmp_path):
    """The environment of a user's shell: ``motiontheater`` on the PATH (this interpreter's), no
    browser to open, matplotlib without a display."""
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    script = bin_dir / "motiontheater"
    script.write_text(f'#!/bin/sh\nexec "{sys.executable}" -m motiontheater "$@"\n')
    script.chmod(0o755)
    return {**os.environ, "PATH": f"{bin_dir}{os.pathsep}{os.environ['PATH']}", "BROWSER": "true", "MPLBACKEND": "Agg"}


def test_every_verb_has_an_example():
    assert len(EXAMPLES) >= 30
    assert set(HELPS) <= {verb for verb, _ in EXAMPLES}


@pytest.mark.parametrize(("verb", "command"), EXAMPLES, ids=[f"{v}-{i}" for i, (v, _) in enumerate(EXAMPLES)])
def test_example_runs_as_pasted(verb, command, data_dir, tmp_path, shell_env):
    folder = tmp_path / "work"
    folder.mkdir()
    user_folder(verb, command, folder)
    done = subprocess.run(
        ["bash", "-c", command], check=False, cwd=folder, env=shell_env, capture_output=True, text=True, timeout=600
    )
    assert done.returncode == 0, f"{command}\n{done.stdout[-2000:]}\n{done.stderr[-2000:]}"
    assert "Traceback" not in done.stderr and "Warning:" not in done.stderr, done.stderr


@pytest.mark.parametrize("verb", [None, *HELPS])
def test_help_has_no_docstring_markup(verb):
    text = build_parser().format_help() if verb is None else HELPS[verb]  # None: the verbs' list
    for markup in (r":[a-z]+:`", r"``", r"\bReturns\b"):
        assert not re.search(markup, text), f"motiontheater {verb} --help shows {markup}: {text}"


def test_steps_help_says_what_it_lists():
    assert "as a recipe's [[step]] table writes it" in " ".join(HELPS["steps"].split())


def test_steps_lists_options_as_a_recipe_writes_them(capsys):
    assert main(["steps"]) == 0
    tables: dict[str, list[str]] = {}
    for line in capsys.readouterr().out.splitlines():
        if not line.startswith(" "):
            tables[line.split(":")[0]] = []
        else:
            assignment, _, what = line.strip().partition("  # ")
            assert what, line
            # the description is for a recipe's writer: no command-line syntax
            assert "comma-separated" not in what and not re.search(r"(^|\s|\()--\w", what), line
            tomllib.loads(assignment)  # each line is TOML by itself
            tables[list(tables)[-1]].append(assignment)
    assert 'joints = ["lfemur", "rfemur"]' in tables["median"] and "size = 5" in tables["median"]
    for name, lines in tables.items():  # and a recipe of them all is a valid step
        Pipeline.from_toml("\n".join(["[[step]]", f'run = "{name}"', *lines]))
