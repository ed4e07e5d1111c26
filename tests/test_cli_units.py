"""Every verb that offers --unit honours it: the verbs are found in the parser, so a new one is
run here too (and fails until this file says how to run it)."""

import argparse
import os
from pathlib import Path

import pytest

import motiontheater as mt
from motiontheater.cli import build_parser, main

UNIT = "0.45"  # CMU's BVH conversions' unit (inch / 0.45), which their size does not tell
METERS = 0.0254 / 0.45

# the value of a required step option, by kind
VALUES = {"int": "3", "float": "50", "floats": "1,1", "frames": "2:20", "path": "{asf}"}
# steps whose output is not a BVH of the take's skeleton
OUTPUTS = {"convert": "out.amc", "retarget": "out.amc"}
# the verbs that are not steps: their arguments ({take}, {asf}, {recipe} filled in) and outputs
OTHERS = {
    "info": ["info", "{take}", "--json"],
    "filter": ["filter", "{take}", "--median", "3", "-o", "out.bvh"],
    "apply": ["apply", "{take}", "--recipe", "{recipe}", "-o", "out.bvh"],
    "batch": ["batch", "{take}", "--recipe", "{recipe}", "-o", "out", "--quiet", "--jobs", "1"],
    "check": ["check", "{take}", "-o", "report.json", "--quiet", "--jobs", "1"],
    "skate": ["skate", "{take}", "--json"],
    "contacts": ["contacts", "{take}", "-o", "contacts.csv"],
    "view": ["view", "{take}", "--no-open", "-o", "page.html"],
    "plot": ["plot", "{take}", "--joints", "root", "-o", "fig.png"],
    "render": ["render", "{take}", "-o", "anim.gif", "--fps", "5", "--size", "64x48", "--frames", "1:60"],
}
NOT_COMPARED = {"manifest.json"}  # batch's record of the run: its times differ from run to run


def unit_verbs() -> dict[str, argparse.ArgumentParser]:
    """The verbs whose parser offers --unit, by name (not by alias)."""
    subparsers = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    return {
        name: parser
        for name, parser in subparsers.choices.items()
        if parser.prog == f"motiontheater {name}" and any("--unit" in a.option_strings for a in parser._actions)
    }


def runs() -> list[tuple[str, bool]]:
    """(verb, dry run): each verb, and again with --dry-run where it offers one."""
    found = []
    for name, parser in unit_verbs().items():
        found.append((name, False))
        if any("--dry-run" in a.option_strings for a in parser._actions):
            found.append((name, True))
    return found


def arguments(verb: str, dry_run: bool) -> list[str]:
    if verb in OTHERS:
        return list(OTHERS[verb])
    step = mt.steps().get(verb)
    assert step is not None, f"say in OTHERS how to run the verb {verb}, which offers --unit"
    argv = [verb, "{take}"]
    for option in step.all_options:
        if option.required:
            assert option.kind in VALUES, f"say in VALUES what to give a required {option.kind} option ({verb})"
            argv += [option.flag, VALUES[option.kind]]
    if dry_run:
        return [*argv, "--dry-run"]
    return [*argv, "-o", "out" + step.suffixes[0] if step.is_exporter else OUTPUTS.get(verb, "out.bvh")]


@pytest.fixture(scope="module")
def files(data_dir, tmp_path_factory):
    """A short take (240 frames) whose length unit cannot be told from its size, a recipe whose result depends
    on the unit (the footskate cleanup's thresholds are in metres), and an ASF target."""
    folder = tmp_path_factory.mktemp("units")
    take = folder / "short.bvh"
    # at 100 Hz: a frame time a BVH writes exactly, so that resampling to 50 Hz is a simple ratio
    mt.write_bvh(mt.read_bvh(data_dir / "cmu" / "01_01.bvh").crop(1, 240).replace(frame_rate=100.0), take)
    # named otherwise than CMU's conversion names its hips, its 26 units tell no unit
    take.write_bytes(take.read_bytes().replace(b"HipJoint", b"Hip_"))
    assert mt.read_bvh(take).skeleton.length_source == "assumed"
    recipe = folder / "recipe.toml"
    recipe.write_text('[[step]]\nrun = "cleanup"\n')
    return {"take": str(take), "recipe": str(recipe), "asf": str(data_dir / "cmu" / "01.asf")}


def produce(argv: list[str], folder: Path, capsys) -> tuple:
    """What a run makes: its status, what it printed and the files it wrote (in ``folder``)."""
    folder.mkdir()
    here = os.getcwd()
    os.chdir(folder)
    try:
        status = main(argv)
    finally:
        os.chdir(here)
    printed = capsys.readouterr()
    written = {
        str(p.relative_to(folder)): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file() and p.name not in NOT_COMPARED
    }
    return status, printed.out, printed.err, written


@pytest.mark.parametrize(("verb", "dry_run"), runs(), ids=lambda v: {True: "dry-run", False: ""}.get(v, v))
def test_every_verb_that_offers_unit_uses_it(verb, dry_run, files, tmp_path, capsys):
    """Run with --unit and without: what the verb makes must differ (a dropped flag makes the
    same), and with it the verb succeeds."""
    if verb == "c3d":
        pytest.importorskip("c3d")
    argv = [word.format(**files) for word in arguments(verb, dry_run)]
    given = produce([*argv, "--unit", UNIT], tmp_path / "given", capsys)
    assert given[0] == 0, given[2]
    assert produce(argv, tmp_path / "told", capsys) != given, f"{verb} made the same without --unit {UNIT}"


def test_the_given_unit_is_the_one_used(files, tmp_path, capsys):
    """Where a verb says the unit (info, retarget --dry-run) or writes it (view's page), it is
    the unit given."""
    import json

    from test_view import page_data

    assert main(["info", files["take"], "--json", "--unit", UNIT]) == 0
    unit = json.loads(capsys.readouterr().out)["length_unit"]
    assert unit["source"] == "given" and unit["meters_per_unit"] == pytest.approx(METERS)
    assert main(["retarget", files["take"], "--to", files["asf"], "--dry-run", "--unit", UNIT]) == 0
    assert "source in/0.45 = 0.0564444 m" in capsys.readouterr().out
    page = tmp_path / "page.html"
    assert main(["view", files["take"], "--no-open", "-o", str(page), "--unit", UNIT]) == 0
    assert page_data(page.read_text(encoding="utf-8"))["takes"][0]["metersPerUnit"] == pytest.approx(METERS)


def test_the_verbs_are_found():
    """The verbs that read takes offer --unit (a parser change that hid them would empty the test)."""
    assert {"info", "filter", "batch", "view", "plot", "render", "retarget", "median"} <= set(unit_verbs())


@pytest.mark.parametrize(("verb", "dry_run"), runs(), ids=lambda v: {True: "dry-run", False: ""}.get(v, v))
def test_every_verb_that_reads_takes_uses_a_given_body(verb, dry_run, files, tmp_path, capsys):
    """--body comes with --unit (one option function): a joint the take does not have is refused by
    every verb, naming it, and nothing is written; a dropped flag would run as without it."""
    if verb == "c3d":
        pytest.importorskip("c3d")
    argv = [word.format(**files) for word in arguments(verb, dry_run)]
    status, _, err, written = produce([*argv, "--body", "Nowhere"], tmp_path / "given", capsys)
    assert status != 0 and "no joint 'Nowhere' to carry the body" in err, (status, err)
    assert not {name for name in written if not name.endswith("manifest.json")}, written


def test_a_given_body_is_the_body(data_dir, tmp_path, capsys):
    import json

    take = data_dir / "bvh" / "walk01.bvh"
    assert main(["info", str(take), "--json", "--body", "Hips"]) == 0
    assert json.loads(capsys.readouterr().out)["body"]["joint"] == "Hips"
    assert main(["info", str(take), "--body", "LeftUpLeg"]) == 2  # the hips above it move
    assert "the body joint 'LeftUpLeg' chosen has joints above it that move (Hips)" in capsys.readouterr().err


def test_feet_measures_at_an_assumed_unit_say_so(files):
    """skate, contacts, cleanup and view's contacts measure in metres: at an assumed unit, a warning."""
    take = mt.read_bvh(files["take"])
    with pytest.warns(UserWarning, match=r"length unit is assumed \(cm\).*--unit UNIT"):
        mt.skate_metrics(take)
    given = mt.read_bvh(files["take"], unit=UNIT)
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        mt.skate_metrics(given)
