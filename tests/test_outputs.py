"""Outputs never replace an input or each other, inputs are regular files, and chains of verbs work:
each case run through the command line, every input byte-identical afterwards."""

import contextlib
import hashlib
import os
import shutil
import signal
import socket
from pathlib import Path

import pytest

from motiontheater.cli import main
from motiontheater.databases import batch
from motiontheater.editing.pipeline import Pipeline


def digests(folder: Path) -> dict[str, str]:
    """Every regular file below a folder and the hash of its bytes."""
    return {
        str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file() and not p.is_symlink()
    }


@contextlib.contextmanager
def within(seconds: int):
    """Fail, rather than hang, when the block takes longer (a FIFO read waits for a writer forever)."""

    def expired(signum, frame):
        raise TimeoutError(f"still running after {seconds} s")

    previous = signal.signal(signal.SIGALRM, expired)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


@pytest.fixture
def cmu(copies):
    """A folder with subject 01's skeleton and its take in ASF/AMC and in BVH."""
    return copies("cmu", ("01.asf", "01_01.amc", "01_01.bvh"))


def test_batch_into_a_folder_of_its_inputs_is_refused(cmu, capsys):
    sub = cmu / "sub"
    sub.mkdir()
    shutil.copy(cmu / "01.asf", sub / "01.asf")
    shutil.copy(cmu / "01_01.amc", sub / "01_01.amc")
    before = digests(cmu)
    assert main(["batch", "--median", "5", "--jobs", "1", str(cmu), "-o", str(sub), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert f"{sub / '01_01.amc'}, the output of {cmu / '01_01.amc'}, would replace {sub / '01_01.amc'}" in err
    assert digests(cmu) == before


def test_batch_into_its_own_folder_needs_in_place(cmu, capsys):
    before = digests(cmu)
    assert main(["batch", "--median", "5", "--jobs", "1", str(cmu / "01_01.amc"), "-o", str(cmu)]) == 2
    assert "would be overwritten by its own output" in capsys.readouterr().err
    assert digests(cmu) == before
    assert main(["batch", "--median", "5", "--jobs", "1", str(cmu / "01_01.amc"), "-o", str(cmu), "--in-place"]) == 0
    after = digests(cmu)
    assert after["01_01.amc"] != before["01_01.amc"] and after["01.asf"] == before["01.asf"]


def test_two_input_folders_with_one_take_name_mirror_apart(data_dir, tmp_path, capsys):
    a, b, out = tmp_path / "a", tmp_path / "b", tmp_path / "out"
    a.mkdir()
    b.mkdir()
    for name in ("02.asf", "02_01.amc"):
        shutil.copy(data_dir / "cmu" / name, a / name)
    shutil.copy(data_dir / "cmu" / "01.asf", b / "02.asf")  # another skeleton under the same name
    shutil.copy(data_dir / "cmu" / "01_01.amc", b / "02_01.amc")
    before = digests(tmp_path)
    assert main(["batch", "--median", "5", "--jobs", "1", str(a), str(b), "-o", str(out), "--quiet"]) == 0
    assert digests(tmp_path) == {**before, **{k: v for k, v in digests(tmp_path).items() if k.startswith("out")}}
    for folder in (a, b):  # each take beside its own skeleton, under its folder's name
        assert (out / folder.name / "02.asf").read_bytes() == (folder / "02.asf").read_bytes()
        assert main(["info", str(out / folder.name / "02_01.amc")]) == 0
    capsys.readouterr()
    assert main(["batch", "--median", "5", "--resume", "--jobs", "1", str(a), str(b), "-o", str(out)]) == 0
    assert "0 processed, 2 skipped" in capsys.readouterr().out


def test_a_take_in_two_formats_gets_two_outputs_under_an_exporter(cmu, tmp_path, capsys):
    recipe = tmp_path / "positions.toml"
    recipe.write_text('[[step]]\nrun = "positions"\n')
    out = tmp_path / "out"
    before = digests(cmu)
    assert main(["batch", str(cmu), "--recipe", str(recipe), "-o", str(out), "--jobs", "1", "--quiet"]) == 0
    written = sorted(p.name for p in out.glob("*.csv"))
    assert written == ["01_01.amc.csv", "01_01.bvh.csv"]
    assert (out / "01_01.amc.csv").read_bytes() != (out / "01_01.bvh.csv").read_bytes()
    assert digests(cmu) == before
    capsys.readouterr()
    assert main(["batch", str(cmu), "--recipe", str(recipe), "-o", str(out), "--jobs", "1", "--resume"]) == 0
    assert "0 processed, 2 skipped" in capsys.readouterr().out
    # a take alone keeps the plain name
    assert main(["batch", str(cmu / "01_01.bvh"), "--recipe", str(recipe), "-o", str(tmp_path / "one")]) == 0
    assert [p.name for p in (tmp_path / "one").glob("*.csv")] == ["01_01.csv"]


def test_two_takes_claiming_one_output_are_refused(cmu, tmp_path):
    # 01_01.amc -> 01_01.amc.csv (it shares its stem with 01_01.bvh), which 01_01.amc.bvh makes too
    shutil.copy(cmu / "01_01.bvh", cmu / "01_01.amc.bvh")
    pipeline = Pipeline.of("positions")
    with pytest.raises(ValueError, match="would both be written to .*01_01.amc.csv"):
        batch.plan_jobs([str(cmu)], tmp_path / "out", pipeline)
    assert not (tmp_path / "out").exists()


def test_convert_onto_an_existing_skeleton_is_refused(data_dir, cmu, capsys):
    before = digests(cmu)
    walk = data_dir / "bvh" / "walk01.bvh"
    target = cmu / "01.amc"  # its skeleton would be 01.asf, the one 01_01.amc is read with
    assert main(["convert", str(walk), str(target)]) == 2
    assert f"{cmu / '01.asf'} exists and holds another skeleton" in capsys.readouterr().err
    assert digests(cmu) == before and not target.exists()
    assert main(["convert", str(walk), str(target), "--in-place"]) == 0
    assert digests(cmu)["01.asf"] != before["01.asf"]
    assert main(["info", str(target)]) == 0


def test_a_batch_does_not_copy_a_skeleton_over_another(cmu, data_dir, tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    shutil.copy(data_dir / "cmu" / "02.asf", out / "01.asf")
    before = digests(tmp_path)
    assert main(["batch", "--median", "5", "--jobs", "1", str(cmu / "01_01.amc"), "-o", str(out)]) == 2
    assert f"{out / '01.asf'} exists and holds another skeleton" in capsys.readouterr().err
    assert digests(tmp_path) == before
    assert main(["batch", "--median", "5", "--jobs", "1", str(cmu / "01_01.amc"), "-o", str(out), "--in-place"]) == 0
    assert (out / "01.asf").read_bytes() == (cmu / "01.asf").read_bytes()


def not_regular(folder: Path, kind: str, name: str = "x.amc") -> Path:
    """A file named as a take (or as ``name``) that is not a regular file."""
    path = folder / name
    if kind == "device":
        path.symlink_to("/dev/zero")
    elif kind == "fifo":
        os.mkfifo(path)
    elif kind == "socket":
        here = os.getcwd()
        os.chdir(folder)  # a socket's path must be short
        try:
            socket.socket(socket.AF_UNIX).bind(path.name)
        finally:
            os.chdir(here)
    else:
        path.symlink_to(path.name)  # a link to itself
    return path


@pytest.mark.parametrize(
    ("kind", "said"),
    [
        ("device", "a character device, not a regular file"),
        ("fifo", "a named pipe (FIFO), not a regular file"),
        ("socket", "a socket, not a regular file"),
        ("loop", "symlink loop"),
    ],
)
def test_inputs_that_are_not_regular_files_are_refused(cmu, tmp_path, capsys, kind, said):
    bad = not_regular(cmu, kind)
    before = digests(cmu)
    out = tmp_path / "out"
    with within(60):
        assert main(["filter", "--median", "5", str(bad), "-o", str(tmp_path / "y.amc")]) == 2
        assert capsys.readouterr().err.startswith(f"motiontheater filter: {bad}: {said}")
        assert main(["info", str(bad)]) == 2
        assert f"{bad}: {said}" in capsys.readouterr().err
        for given in (bad, cmu):  # named, and found in a folder: reported, the others done
            assert main(["batch", "--median", "5", "--jobs", "1", str(given), "-o", str(out), "--quiet"]) == 1
            assert f"FAILED {bad}: {said}" in capsys.readouterr().err
        # an AMC whose skeleton is not a file
        (cmu / "01.asf").rename(cmu / "real.asf")
        not_regular(cmu, kind, "01.asf")
        assert main(["info", str(cmu / "01_01.amc")]) == 2
        assert f"{cmu / '01.asf'}: {said}" in capsys.readouterr().err
    assert not (tmp_path / "y.amc").exists()
    assert sorted(p.name for p in out.iterdir()) == [batch.MANIFEST, "01.asf", "01_01.amc", "01_01.bvh"]
    (cmu / "01.asf").unlink()
    (cmu / "real.asf").rename(cmu / "01.asf")
    assert digests(cmu) == before


def test_a_chain_of_verbs_works_from_any_folder(cmu, tmp_path, monkeypatch, capsys):
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    before = digests(cmu)
    take = str(cmu / "01_01.amc")
    assert main(["filter", take, "--median", "5", "-o", "out/smooth.amc"]) == 0
    assert "and its skeleton out/smooth.asf" in capsys.readouterr().out
    assert Path("out/smooth.asf").read_bytes() == (cmu / "01.asf").read_bytes()
    assert main(["info", "out/smooth.amc"]) == 0
    assert main(["median", "out/smooth.amc", "--size", "3", "-o", "deeper/again.amc"]) == 0
    assert main(["view", take, "out/smooth.amc", "deeper/again.amc", "--no-open", "-o", "p.html"]) == 0
    assert Path("p.html").stat().st_size > 0
    # an output beside a skeleton that holds its own: nothing more written
    assert main(["filter", take, "--median", "3", "-o", str(cmu / "01_01_smooth.amc")]) == 0
    assert sorted(p.name for p in cmu.glob("*.asf")) == ["01.asf"]
    (cmu / "01_01_smooth.amc").unlink()
    assert digests(cmu) == before


def test_batch_keeps_the_suffix_as_the_take_spells_it(data_dir, tmp_path):
    from motiontheater.cli import main

    folder = tmp_path / "up"
    folder.mkdir()
    shutil.copy(data_dir / "cmu" / "01_01.amc", folder / "01_01.AMC")
    shutil.copy(data_dir / "cmu" / "01.asf", folder / "01.asf")
    assert main(["batch", str(folder), "--median", "3", "-o", str(tmp_path / "out"), "--quiet", "--jobs", "1"]) == 0
    assert sorted(p.name for p in (tmp_path / "out").iterdir() if not p.name.startswith(".")) == ["01.asf", "01_01.AMC"]


@pytest.mark.parametrize("verb", ["apply", "batch", "combine", "retarget"])
def test_a_recipe_or_map_that_is_a_fifo_is_refused_not_waited_on(data_dir, tmp_path, capsys, verb):
    import signal

    from motiontheater.cli import main

    take = tmp_path / "01_01.amc"
    shutil.copy(data_dir / "cmu" / "01_01.amc", take)
    shutil.copy(data_dir / "cmu" / "01.asf", tmp_path / "01.asf")
    fifo = tmp_path / "steps.toml"
    os.mkfifo(fifo)
    argv = {
        "apply": ["apply", str(take), "--recipe", str(fifo), "-o", str(tmp_path / "o.amc")],
        "batch": ["batch", str(take), "--recipe", str(fifo), "-o", str(tmp_path / "out")],
        "combine": ["combine", str(fifo), "-o", str(tmp_path / "o.amc")],
        "retarget": [
            "retarget",
            str(take),
            "--to",
            str(data_dir / "bvh" / "walk01.bvh"),
            "--map",
            str(fifo),
            "-o",
            str(tmp_path / "o.bvh"),
        ],
    }[verb]
    signal.alarm(60)  # a hang fails the test instead of blocking the suite
    try:
        assert main(argv) == 2
    finally:
        signal.alarm(0)
    assert "named pipe (FIFO), not a regular file" in capsys.readouterr().err


def test_a_failed_write_removes_the_folders_it_made(tmp_path):
    from motiontheater._io import output

    (tmp_path / "kept").mkdir()
    with pytest.raises(RuntimeError), output(tmp_path / "kept" / "new" / "deeper" / "a.amc") as f:
        f.write(b"half a take")
        raise RuntimeError("the writer failed")
    assert [p.name for p in tmp_path.rglob("*")] == ["kept"]
    with output(tmp_path / "kept" / "new" / "b.amc") as f:
        f.write(b"whole")
    assert (tmp_path / "kept" / "new" / "b.amc").read_bytes() == b"whole"
    with pytest.raises(RuntimeError), output(tmp_path / "kept" / "new" / "c" / "d.amc") as f:
        raise RuntimeError("the writer failed")
    assert sorted(p.name for p in (tmp_path / "kept").rglob("*")) == ["b.amc", "new"]  # another file keeps it
