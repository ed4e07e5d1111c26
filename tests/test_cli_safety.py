"""Files are sacred, messages are for people: what the command line does around the work itself."""

import errno
import json
import os
import shutil
import stat
import subprocess
import sys

import numpy as np
import pytest

import motiontheater as mt
from motiontheater import _io
from motiontheater.cli import main
from motiontheater.databases import batch
from motiontheater.model import registry


@pytest.fixture
def cmu(copies):
    """A folder with subject 02's skeleton and two of its takes."""
    return copies("cmu", ("02.asf", "02_01.amc", "02_02.amc"))


def test_outputs_get_the_umasks_permissions(cmu, tmp_path):
    previous = os.umask(0o022)
    try:
        assert main(["filter", "--median", "3", str(cmu / "02_01.amc"), "-o", str(tmp_path / "a.amc")]) == 0
        assert main(["batch", "--mean", "3", "--jobs", "1", str(cmu), "-o", str(tmp_path / "b"), "--quiet"]) == 0
        os.umask(0o002)
        mt.write_bvh(mt.to_bvh(mt.read_amc(cmu / "02_01.amc", mt.read_asf(cmu / "02.asf"))), tmp_path / "c.bvh")
    finally:
        os.umask(previous)
    assert stat.S_IMODE((tmp_path / "a.amc").stat().st_mode) == 0o644
    for written in (tmp_path / "b" / "02_02.amc", tmp_path / "b" / "02.asf"):
        assert stat.S_IMODE(written.stat().st_mode) == 0o644, written
    assert stat.S_IMODE((tmp_path / "c.bvh").stat().st_mode) == 0o664


def test_an_input_is_never_overwritten_unless_asked(cmu, capsys):
    take = cmu / "02_01.amc"
    before = take.read_bytes()
    assert main(["filter", "--median", "3", str(take), "-o", str(take)]) == 2
    assert "02_01.amc is the input: write the result to another file, or pass --in-place" in capsys.readouterr().err
    assert main(["median", str(take), str(take), "--size", "3"]) == 2
    assert main(["batch", "--median", "3", "--jobs", "1", str(cmu), "-o", str(cmu)]) == 2
    assert "would be overwritten by its own output" in capsys.readouterr().err
    assert take.read_bytes() == before
    assert main(["filter", "--median", "3", str(take), "-o", str(take), "--in-place"]) == 0
    assert take.read_bytes() != before


def test_resume_redoes_takes_made_by_another_recipe_or_from_changed_inputs(cmu, tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["batch", "--median", "5", "--jobs", "1", str(cmu), "-o", str(out)]) == 0
    capsys.readouterr()
    assert main(["batch", "--median", "5", "--resume", "--jobs", "1", str(cmu), "-o", str(out)]) == 0
    assert "0 processed, 2 skipped" in capsys.readouterr().out
    assert main(["batch", "--mean", "3", "--resume", "--jobs", "1", str(cmu), "-o", str(out)]) == 0
    assert "2 processed, 0 skipped" in capsys.readouterr().out
    expected = mt.read_amc(cmu / "02_01.amc", mt.read_asf(cmu / "02.asf")).mean(size=3)
    np.testing.assert_array_equal(mt.read_amc(out / "02_01.amc", expected.skeleton).values, expected.values)
    (cmu / "02_02.amc").write_bytes((cmu / "02_02.amc").read_bytes())  # rewritten as it was: still done
    assert main(["batch", "--mean", "3", "--resume", "--jobs", "1", str(cmu), "-o", str(out)]) == 0
    assert "0 processed, 2 skipped" in capsys.readouterr().out
    (cmu / "02_02.amc").write_bytes((cmu / "02_02.amc").read_bytes() + b"\n")  # changed
    assert main(["batch", "--mean", "3", "--resume", "--jobs", "1", str(cmu), "-o", str(out)]) == 0
    assert "1 processed, 1 skipped" in capsys.readouterr().out
    (out / "02_01.amc").unlink()
    assert main(["batch", "--mean", "3", "--resume", "--jobs", "1", str(cmu), "-o", str(out)]) == 0
    assert "1 processed, 1 skipped" in capsys.readouterr().out


def test_resume_trusts_the_manifest_lines_a_killed_run_wrote_whole(cmu, tmp_path, capsys):
    """The manifest gets a line as each take finishes: cut in the middle of its last line (a kill as
    it was written), the lines before still count, and the take of the cut line is done again."""
    out = tmp_path / "out"
    assert main(["batch", "--median", "5", "--jobs", "1", str(cmu), "-o", str(out)]) == 0
    manifest = out / batch.MANIFEST
    lines = manifest.read_bytes().splitlines(keepends=True)
    assert len(lines) == 2 and all(json.loads(line)["output"].endswith(".amc") for line in lines)
    manifest.write_bytes(lines[0] + lines[1][: len(lines[1]) // 2])
    capsys.readouterr()
    assert main(["batch", "--median", "5", "--resume", "--jobs", "1", str(cmu), "-o", str(out)]) == 0
    assert "1 processed, 1 skipped" in capsys.readouterr().out
    assert len(manifest.read_bytes().splitlines()) == 2  # compacted: one whole line per output
    entries = [json.loads(line) for line in lines]
    manifest.unlink()  # as earlier releases wrote it, under its name then
    (out / ".motiontheater-batch.json").write_text(
        json.dumps({"version": 1, "outputs": {e.pop("output"): e for e in entries}})
    )
    assert main(["batch", "--median", "5", "--resume", "--jobs", "1", str(cmu), "-o", str(out)]) == 0
    assert "0 processed, 2 skipped" in capsys.readouterr().out
    assert main(["batch", "--mean", "3", "--resume", "--jobs", "1", str(cmu), "-o", str(out)]) == 0
    assert manifest.exists() and not (out / ".motiontheater-batch.json").exists()  # carried over


def test_the_output_suffix_decides_the_format(cmu, tmp_path, capsys):
    assert main(["filter", "--median", "3", str(cmu / "02_01.amc"), "-o", str(tmp_path / "out.bvh")]) == 2
    assert capsys.readouterr().err == (
        f"motiontheater filter: {tmp_path / 'out.bvh'}: this is a motion of an ASF skeleton, which is written as "
        ".amc, not .bvh; name the output .amc, or convert it first (motiontheater convert)\n"
    )
    assert not (tmp_path / "out.bvh").exists()
    assert main(["median", str(cmu / "02_01.amc"), "-o", str(tmp_path / "out.txt"), "--size", "3"]) == 2
    assert "out.txt: a take's file name must end in .amc, .bvh, .glb or .gltf" in capsys.readouterr().err


def test_messages_name_the_users_paths(cmu, tmp_path, capsys):
    assert main(["filter", "--median", "3", str(cmu / "nothere.amc"), "-o", str(tmp_path / "x.amc")]) == 2
    assert capsys.readouterr().err.strip() == f"motiontheater filter: {cmu / 'nothere.amc'}: no such file"
    (cmu / "02_empty.amc").write_bytes(b"")
    assert main(["filter", "--median", "3", str(cmu / "02_empty.amc"), "-o", str(tmp_path / "x.amc")]) == 2
    assert "02_empty.amc: the take holds no frames" in capsys.readouterr().err
    (cmu / "empty.amc").write_bytes(b"")
    assert main(["filter", "--median", "3", str(cmu / "empty.amc"), "-o", str(tmp_path / "x.amc")]) == 2
    err = capsys.readouterr().err
    assert "no skeleton for" in err and "give it with --asf" in err
    assert not (tmp_path / "x.amc").exists()
    assert main(["convert", str(cmu / "02_01.amc"), str(tmp_path / "y.bvh"), "--asf", str(cmu / "nothere.asf")]) == 2
    # the skeleton named, not the take
    assert capsys.readouterr().err.strip() == f"motiontheater convert: {cmu / 'nothere.asf'}: no such file"


def test_an_output_problem_every_take_would_meet_stops_the_batch_once(cmu, tmp_path, capsys, monkeypatch):
    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    out = tmp_path / "out"
    out.mkdir()
    monkeypatch.setattr(_io, "_partial", full)
    assert main(["batch", "--median", "3", "--jobs", "1", str(cmu), "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert "STOPPED: cannot write" in err and "No space left on device" in err
    assert "1 takes were not processed" in err
    assert err.count("No space left on device") == 1 and ".mt-partial" not in err


def test_an_unwritable_output_folder_is_one_clear_message(cmu, tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    assert main(["batch", "--median", "3", "--jobs", "1", str(cmu), "-o", str(blocker / "out")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "cannot write to the output folder" in err


def test_interrupting_a_single_file_job_leaves_nothing_and_says_so(cmu, tmp_path, capsys):
    @registry.step("toy_interrupted", "a step the user interrupts")
    def toy(motion):
        raise KeyboardInterrupt

    try:
        assert main(["toy_interrupted", str(cmu / "02_01.amc"), "-o", str(tmp_path / "x.amc")]) == 130
    finally:
        registry.unregister("toy_interrupted")
    assert capsys.readouterr().err == "motiontheater toy_interrupted: interrupted; nothing was left half-written\n"
    assert list(tmp_path.glob("*.amc")) == [] and list(tmp_path.glob(".mt-partial*")) == []


def test_a_closed_pipe_ends_quietly(cmu):
    shell = f"{sys.executable} -m motiontheater steps | true; echo ${{PIPESTATUS[0]}}"
    for _ in range(3):  # the reader may be gone before the first write, or only after it
        done = subprocess.run(["bash", "-c", shell], capture_output=True, text=True, check=True)
        assert done.stdout.strip() == "0" and done.stderr == "", done.stderr


def test_stale_partials_of_killed_writers_are_removed(cmu, tmp_path):
    dead = subprocess.run(
        [sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True, check=True
    )
    stale = tmp_path / f"{_io.PARTIAL_PREFIX}{dead.stdout.strip()}-abc.tmp"
    live = tmp_path / f"{_io.PARTIAL_PREFIX}{os.getpid()}-def.tmp"
    stale.write_bytes(b"half")
    live.write_bytes(b"being written")
    assert main(["filter", "--median", "3", str(cmu / "02_01.amc"), "-o", str(tmp_path / "x.amc")]) == 0
    assert not stale.exists() and live.exists()


def test_the_command_line_reaches_what_the_api_does(cmu, data_dir, tmp_path, capsys):
    # positions of a BVH, and of an AMC whose skeleton is found beside it
    assert main(["positions", str(data_dir / "bvh" / "walk01.bvh"), "-o", str(tmp_path / "w.csv")]) == 0
    assert main(["positions", str(cmu / "02_01.amc"), "-o", str(tmp_path / "a.npz")]) == 0
    # joints with blanks after the commas
    assert main(["median", str(cmu / "02_01.amc"), "-o", str(tmp_path / "m.amc"), "--size", "3",
                 "--joints", "lfemur, rfemur"]) == 0  # fmt: skip
    # a joint without channels is refused, not ignored
    assert main(["median", str(cmu / "02_01.amc"), "-o", str(tmp_path / "n.amc"), "--size", "3",
                 "--joints", "lfemur,lhipjoint"]) == 2  # fmt: skip
    assert "joint 'lhipjoint' has no channels" in capsys.readouterr().err
    # a frame range
    assert main(["median", str(cmu / "02_01.amc"), "-o", str(tmp_path / "r.amc"), "--size", "5",
                 "--frames", "100:200"]) == 0  # fmt: skip
    motion = mt.read_amc(cmu / "02_01.amc", mt.read_asf(cmu / "02.asf"))
    ranged = mt.read_amc(tmp_path / "r.amc", motion.skeleton)
    np.testing.assert_array_equal(ranged.values[:99], motion.values[:99])
    np.testing.assert_array_equal(ranged.values[200:], motion.values[200:])
    # BVH tracks in a combine recipe
    walk = data_dir / "bvh" / "walk01.bvh"
    shutil.copy(walk, tmp_path / "walk.bvh")
    (tmp_path / "scene.toml").write_text(
        '[base]\nmotion = "walk.bvh"\n[[track]]\nmotion = "walk.bvh"\ncut = [10, 40]\nscale = [10, 70]\n'
    )
    assert main(["combine", str(tmp_path / "scene.toml"), "-o", str(tmp_path / "scene.bvh")]) == 0
    assert mt.read_bvh(tmp_path / "scene.bvh").frames == mt.read_bvh(walk).frames
    # the dry run says where the piece comes from, and what the blends read besides
    (tmp_path / "blend.toml").write_text(
        '[base]\nmotion = "walk.bvh"\n[[track]]\nmotion = "walk.bvh"\ncut = [30, 60]\nblend = 5\n'
    )
    capsys.readouterr()
    assert main(["combine", str(tmp_path / "blend.toml"), "--dry-run"]) == 0
    assert "piece 30..60 from source frames 30..60 (the blends also read source frames 25..65)" in (
        capsys.readouterr().out
    )
