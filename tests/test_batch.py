"""Batch processing: the corpus on 2 processes and on Dask, kills and resumes, failures, streaming."""

import dataclasses
import os
import re
import shutil
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

import motiontheater as mt
from motiontheater.cli import main
from motiontheater.databases import batch
from motiontheater.editing import streaming
from motiontheater.model import registry


def expected_bytes(take: Path, kind="median", size=5) -> bytes:
    """The take filtered alone, in memory, as write_amc or write_bvh writes it."""
    out = Path(os.environ.get("TMPDIR", "/tmp")) / f"expected-{os.getpid()}{take.suffix}"
    if take.suffix == ".bvh":
        mt.write_bvh(mt.filter_motion(mt.read_bvh(take), kind, size=size), out)
    else:
        motion = mt.read_amc(take, mt.read_asf(mt.skeleton_path_for(take)))
        mt.write_amc(mt.filter_motion(motion, kind, size=size), out)
    data = out.read_bytes()
    out.unlink()
    return data


@pytest.fixture(scope="module")
def corpus_expected(data_dir):
    takes = sorted([*data_dir.rglob("*.amc"), *data_dir.rglob("*.bvh")])
    return {take.relative_to(data_dir): expected_bytes(take) for take in takes}


def assert_outputs(out: Path, expected: dict) -> None:
    for relative, data in expected.items():
        assert (out / relative).read_bytes() == data, relative
    assert not list(out.rglob(".mt-partial-*"))


def test_corpus_on_two_processes_is_bit_identical_to_each_file_alone(data_dir, tmp_path, corpus_expected, capsys):
    out = tmp_path / "out"
    assert main(["batch", "--median", "5", "--jobs", "2", str(data_dir), "-o", str(out)]) == 0
    assert_outputs(out, corpus_expected)
    assert (out / "cmu" / "01.asf").read_bytes() == (data_dir / "cmu" / "01.asf").read_bytes()
    count = len(corpus_expected)
    assert re.match(
        rf"{count} processed, 0 skipped \(already done\), 0 failed of {count} takes", capsys.readouterr().out
    )


def test_corpus_on_a_dask_local_cluster(data_dir, tmp_path, corpus_expected):
    pytest.importorskip("dask.distributed")
    out = tmp_path / "out"
    jobs, settled = batch.plan_jobs([str(data_dir)], out, mt.Pipeline.of("median", size=5))
    summary = batch.run(jobs, settled, workers=2, dask_local=True, out=out)
    assert not summary.failed and len(summary.results) == len(corpus_expected)
    assert_outputs(out, corpus_expected)


def test_takes_go_to_the_workers_in_groups_and_each_is_reported(data_dir, tmp_path):
    """Many small takes: the workers get them a group at a time (several per message), and every
    take still gets its own result, output and manifest line, as processed alone."""
    src = tmp_path / "in"
    src.mkdir()
    for i in range(70):
        shutil.copyfile(data_dir / "edge" / "test.asf", src / f"take{i:02d}.asf")
        shutil.copyfile(data_dir / "edge" / "test.amc", src / f"take{i:02d}.amc")
    jobs, settled = batch.plan_jobs([str(src)], tmp_path / "out", mt.Pipeline.of("mean", size=3))
    groups = batch._groups(jobs, 2)
    assert [job for group in groups for job in group] == jobs and max(map(len, groups)) > 1
    summary = batch.run(jobs, settled, workers=2, out=tmp_path / "out")
    assert not summary.failed and sorted(r.input for r in summary.results) == sorted(j.input for j in jobs)
    expected = expected_bytes(data_dir / "edge" / "test.amc", "mean", 3)
    assert all((tmp_path / "out" / f"take{i:02d}.amc").read_bytes() == expected for i in range(70))
    manifest = batch.Manifest(tmp_path / "out")
    assert all(manifest.done(job) for job in jobs)
    assert not manifest.done(dataclasses.replace(jobs[0], pipeline=mt.Pipeline.of("mean", size=5)))  # another recipe


def test_a_bad_take_is_reported_and_the_others_go_on(data_dir, tmp_path, capsys):
    src = tmp_path / "in"
    shutil.copytree(data_dir / "cmu", src)
    text = (src / "02_02.amc").read_bytes()
    (src / "02_02.amc").write_bytes(text.replace(b"lfemur ", b"lfemur x ", 1))
    out = tmp_path / "out"
    assert main(["batch", "--mean", "3", "--jobs", "2", str(src), "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert "11 processed, 0 skipped (already done), 1 failed of 12 takes" in err  # 10 AMC, 2 BVH
    assert re.search(r"FAILED .*02_02\.amc, line \d+: expected a number as value 1 of bone 'lfemur', found 'x'", err)
    assert not (out / "02_02.amc").exists() and (out / "02_01.amc").exists()


def test_json_summary(data_dir, tmp_path, capsys):
    import json

    out = tmp_path / "out"
    assert main(["batch", "--binomial", "3", "--json", "--jobs", "1", str(data_dir / "edge"), "-o", str(out)]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["processed"] == 1 and report["failed"] == 0 and report["results"][0]["frames"] == 300


def test_resume_skips_what_is_done(data_dir, tmp_path, capsys):
    src, out = tmp_path / "in", tmp_path / "out"
    shutil.copytree(data_dir / "cmu", src)
    assert main(["batch", "--median", "3", "--jobs", "1", str(src), "-o", str(out)]) == 0
    capsys.readouterr()
    assert main(["batch", "--median", "3", "--resume", "--jobs", "1", str(src), "-o", str(out)]) == 0
    assert "0 processed, 12 skipped (already done), 0 failed of 12 takes\n" in capsys.readouterr().out
    later = (out / "02_01.amc").stat().st_mtime + 10
    os.utime(src / "02_01.amc", (later, later))  # touched, not changed: its content tells
    assert main(["batch", "--median", "3", "--resume", "--jobs", "1", str(src), "-o", str(out)]) == 0
    assert "0 processed, 12 skipped (already done)" in capsys.readouterr().out
    text = (src / "02_01.amc").read_bytes()
    changed = text.replace(b"lfemur 1", b"lfemur 2", 1)  # a value changed, the size kept
    assert changed != text and len(changed) == len(text)
    (src / "02_01.amc").write_bytes(changed)
    assert main(["batch", "--median", "3", "--resume", "--jobs", "1", str(src), "-o", str(out)]) == 0
    assert "1 processed, 11 skipped (already done)" in capsys.readouterr().out
    asf = (src / "02.asf").read_bytes()
    (src / "02.asf").write_bytes(asf.replace(b"length 2", b"length 3", 1))  # the skeleton of 02_*.amc
    command = ["batch", "--median", "3", "--resume", "--in-place", "--jobs", "1", str(src), "-o", str(out)]
    assert main(command) == 0  # --in-place: the ASF beside the outputs is the old one
    done = sum(1 for p in src.glob("02_*.amc"))
    assert f"{done} processed, {12 - done} skipped (already done)" in capsys.readouterr().out


def test_killing_a_run_leaves_no_partial_outputs_and_resume_completes_it(data_dir, tmp_path):
    src = tmp_path / "in"
    for copy in range(12):  # enough work to be caught midway
        shutil.copytree(data_dir / "hdm05", src / f"copy{copy:02d}")
    out = tmp_path / "out"
    command = [
        sys.executable,
        "-m",
        "motiontheater",
        "batch",
        "--median",
        "5",
        "--jobs",
        "2",
        str(src),
        "-o",
        str(out),
        "--quiet",
    ]
    run = subprocess.Popen(command, stderr=subprocess.PIPE, text=True)
    # the signal goes once outputs exist, so the run has its handlers (a loaded machine may take minutes)
    deadline = time.time() + 600
    while time.time() < deadline and run.poll() is None and len(list(out.rglob("*.amc"))) < 20:
        time.sleep(0.01)
    assert run.poll() is None, "the run ended before it could be interrupted"
    assert len(list(out.rglob("*.amc"))) >= 20, "the run wrote nothing in ten minutes"
    run.send_signal(signal.SIGTERM)
    _, stopped = run.communicate(timeout=60)
    assert run.returncode == 130
    assert "INTERRUPTED" in stopped and "--resume" in stopped
    done = list(out.rglob("*.amc"))
    assert 0 < len(done) < 12 * 33, "the run was not caught midway"
    assert not list(out.rglob(".mt-partial-*"))
    expected = {}
    for take in done:  # whatever was written is complete
        relative = take.relative_to(out)
        expected[relative] = expected.get(relative) or expected_bytes(src / relative)
        assert take.read_bytes() == expected[relative], relative
    finished = subprocess.run(command[:-1] + ["--resume"], check=False, capture_output=True, text=True)
    assert finished.returncode == 0, finished.stderr
    # the manifest holds every take the parent saw finish: at most those on disk (a worker may finish
    # one in the moment the parent stops listening; resume does that one again)
    skipped = int(re.search(r"(\d+) skipped \(already done\)", finished.stdout).group(1))
    assert 0 < skipped <= len(done)
    assert "Traceback" not in stopped + finished.stderr
    assert len(list(out.rglob("*.amc"))) == 12 * 33
    sample = out / "copy07" / "HDM_bd_squat1Reps_003_120.amc"
    assert sample.read_bytes() == expected_bytes(src / "copy07" / "HDM_bd_squat1Reps_003_120.amc")


@pytest.mark.parametrize("kind,size", [("mean", 7), ("binomial", 5), ("median", 3)])
def test_streaming_equals_whole(data_dir, tmp_path, kind, size):
    """Small read blocks and chunks, so that every cut is exercised: the same bytes as whole."""
    take = data_dir / "cmu" / "01_01.amc"
    skeleton = mt.read_asf(data_dir / "cmu" / "01.asf")
    pipeline = mt.Pipeline.of(kind, size=size)
    frames = streaming.stream(take, tmp_path / "s.amc", skeleton, pipeline, chunk_frames=300, read_bytes=20_000)
    assert frames == 2751
    assert (tmp_path / "s.amc").read_bytes() == expected_bytes(take, kind, size)


class PeakAndNeighbours:
    """A second streamer, written to the protocol alone: each frame minus its channel's peak over
    the take (a whole-take survey), plus its two neighbours (a halo), frames counted in a state."""

    halo, block = 1, 1

    def survey(self, values, peak):
        return values.max(axis=0) if peak is None else np.maximum(peak, values.max(axis=0))

    def prepare(self, values, state):
        return values.copy(), (state or 0) + len(values)

    def process(self, prepared, peak):
        padded = np.concatenate([prepared[:1], prepared, prepared[-1:]])
        return prepared - peak + (padded[:-2] + padded[2:])


@pytest.fixture
def peak_step():
    @registry.step("peak_and_neighbours", "a test's streamable step", streamer=lambda skeleton: PeakAndNeighbours())
    def peak_and_neighbours(motion: mt.Motion) -> mt.Motion:
        streamer = PeakAndNeighbours()
        return motion.replace(values=streamer.process(motion.values, streamer.survey(motion.values, None)))

    yield peak_and_neighbours
    registry.unregister("peak_and_neighbours")


def test_a_step_streams_through_the_streamer_protocol(data_dir, tmp_path, peak_step):
    take = data_dir / "cmu" / "01_01.amc"
    skeleton = mt.read_asf(data_dir / "cmu" / "01.asf")
    pipeline = mt.Pipeline.of("peak_and_neighbours")
    assert streaming.streamable(pipeline)
    frames = streaming.stream(take, tmp_path / "s.amc", skeleton, pipeline, chunk_frames=300, read_bytes=20_000)
    assert frames == 2751
    mt.write_amc(peak_step(mt.read_amc(take, skeleton)), tmp_path / "whole.amc")
    assert (tmp_path / "s.amc").read_bytes() == (tmp_path / "whole.amc").read_bytes()


def test_streaming_reports_bad_lines_with_their_file_line(data_dir, tmp_path):
    text = (data_dir / "cmu" / "01_01.amc").read_bytes()
    lines = text.split(b"\r\n")
    lines[5000] = lines[5000] + b" 99"
    (tmp_path / "bad.amc").write_bytes(b"\r\n".join(lines))
    skeleton = mt.read_asf(data_dir / "cmu" / "01.asf")
    with pytest.raises(mt.CountError, match=rf"bad.amc, line 5001: bone '{lines[5000].split()[0].decode()}' takes"):
        streaming.stream(
            tmp_path / "bad.amc", tmp_path / "o.amc", skeleton, mt.Pipeline.of("mean", size=3), read_bytes=20_000
        )
    assert not (tmp_path / "o.amc").exists()


@pytest.mark.parametrize("extra,error", [(b":SAMPLES-PER-SECOND", mt.FormatError), (b":RADIANS", mt.FormatError)])
def test_streaming_reads_the_header_as_read_amc_does(data_dir, tmp_path, extra, error):
    text = (data_dir / "cmu" / "01_01.amc").read_bytes()
    (tmp_path / "h.amc").write_bytes(extra + b"\r\n" + text)
    skeleton = mt.read_asf(data_dir / "cmu" / "01.asf")
    with pytest.raises(error) as whole:
        mt.read_amc(tmp_path / "h.amc", skeleton)
    with pytest.raises(error) as streamed:
        streaming.stream(tmp_path / "h.amc", tmp_path / "o.amc", skeleton, mt.Pipeline.of("mean", size=3))
    assert str(streamed.value) == str(whole.value)
    assert not (tmp_path / "o.amc").exists()


def long_take(data_dir: Path, path: Path, frames: int) -> Path:
    """The real 01_01 repeated to ``frames`` frames."""
    text = (data_dir / "cmu" / "01_01.amc").read_bytes()
    first = re.search(rb"(?m)^1\s*$", text).start()
    blocks = re.split(rb"(?m)^\d+\s*\r?\n", text[first:])[1:]
    with open(path, "wb") as f:
        f.write(text[:first])
        for i in range(frames):
            f.write(b"%d\r\n" % (i + 1))
            f.write(blocks[i % len(blocks)])
    return path


def test_streaming_memory_does_not_grow_with_the_take(data_dir, tmp_path):
    """Fifteen and thirty minutes (108,000 and 216,000 frames) stream with the same peak memory: the
    take in memory would add at least its values, 54 MB for the quarter hour more (the bytes equal
    processing whole: test_streaming_equals_whole)."""
    script = textwrap.dedent(f"""
        import re, sys, motiontheater as mt
        from motiontheater.editing import streaming
        skeleton = mt.read_asf({str(data_dir / "cmu" / "01.asf")!r})
        streaming.stream(sys.argv[1], sys.argv[2], skeleton, mt.Pipeline.of("median", size=5))
        print(int(re.search(r"VmHWM:\\s+(\\d+)", open("/proc/self/status").read()).group(1)) * 1024)
    """)

    def peak(frames: int) -> int:
        take = long_take(data_dir, tmp_path / f"{frames}.amc", frames)
        done = subprocess.run(
            [sys.executable, "-c", script, str(take), str(tmp_path / "out.amc")],
            check=False,
            capture_output=True,
            text=True,
        )
        assert done.returncode == 0, done.stderr
        take.unlink()
        return int(done.stdout)

    quarter, half = peak(108_000), peak(216_000)
    assert half - quarter < 30e6, f"peak {quarter / 1e6:.0f} MB for 15 minutes, {half / 1e6:.0f} MB for 30"


def test_batch_streams_takes_above_the_threshold(data_dir, tmp_path, capsys):
    out = tmp_path / "out"
    assert (
        main(
            [
                "batch",
                "--median",
                "5",
                "--json",
                "--stream-above",
                "1",
                "--jobs",
                "1",
                str(data_dir / "cmu" / "01_01.amc"),
                str(data_dir / "cmu" / "02_01.amc"),
                "-o",
                str(out),
            ]
        )
        == 0
    )
    import json

    report = json.loads(capsys.readouterr().out)
    assert report["streamed"] == 1  # 01_01 is 2.2 MB, 02_01 is smaller
    assert (out / "01_01.amc").read_bytes() == expected_bytes(data_dir / "cmu" / "01_01.amc")


def test_inputs_files_folders_and_globs(data_dir, tmp_path):
    found = dict(
        batch.find_takes(
            [str(data_dir / "hdm05" / "HDM_bd_*.amc"), str(data_dir / "edge"), str(data_dir / "cmu" / "02_01.amc")]
        )
    )
    assert len(found) == 11 + 1 + 1
    assert len(batch.find_takes([str(data_dir / "bvh")])) == 8
    # several input folders: a subfolder of the output each, named as the folder
    assert found[data_dir / "edge" / "test.amc"] == Path("edge/test.amc")
    assert found[data_dir / "cmu" / "02_01.amc"] == Path("cmu/02_01.amc")
    assert found[data_dir / "hdm05" / "HDM_bd_squat1Reps_003_120.amc"] == Path("hdm05/HDM_bd_squat1Reps_003_120.amc")
    # one folder, or files of one folder: the output folder itself
    assert dict(batch.find_takes([str(data_dir / "edge")]))[data_dir / "edge" / "test.amc"] == Path("test.amc")
    alone = batch.find_takes([str(data_dir / "cmu" / "02_01.amc"), str(data_dir / "cmu" / "02_02.amc")])
    assert [relative for _, relative in alone] == [Path("02_01.amc"), Path("02_02.amc")]
    with pytest.raises(FileNotFoundError, match="no file, folder or glob match"):
        batch.find_takes([str(tmp_path / "nothing.amc")])


def test_progress_bar(capsys):
    progress = batch.Progress(2, 2_000_000, enabled=True)
    progress.advance(batch.Result("a", "b", bytes=1_000_000))
    progress.close()
    err = capsys.readouterr().err
    assert "1/2 takes" in err and "50%" in err and "1.00M/2.00M" in err
    silent = batch.Progress(2, 10, enabled=False)
    silent.advance(batch.Result("a", "b", bytes=5))
    assert capsys.readouterr().err == ""
