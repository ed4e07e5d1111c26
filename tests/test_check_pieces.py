"""A take of any length is checked a piece at a time, and an AMC larger than a threshold as it
is read: what is found is what checking it whole finds, and the memory it takes does not grow
with the take."""

import collections
import dataclasses
import re
import tracemalloc

import numpy as np
import pytest

import motiontheater as mt
from corpus import DATA, real_files
from motiontheater.databases import pieces, survey
from motiontheater.databases.check import check_motion
from motiontheater.databases.findings import Finding

LONG = [
    p
    for p in real_files("cmu/*.amc") + real_files("cmu/*.bvh")
    if p.name in ("01_01.amc", "135_06-martialArts.amc", "01_01.bvh")
]


def _key(f):
    return (f.kind, f.joints, f.first, f.last, f.severity)


@pytest.mark.parametrize("path", LONG, ids=lambda p: p.name)
def test_a_take_checked_in_pieces_finds_what_it_does_whole(path, monkeypatch):
    """Pieces of 1,000 frames (8 s at 120 Hz), each read with 3 s of its neighbours: every medium
    and high finding is the one the whole take gives, and the low ones but for a few (at the
    seams, and a channel dead in some pieces, whose joint holds still in others)."""
    take = mt.read_take(path)
    monkeypatch.setattr(pieces, "PIECE_FRAMES", 10**9)
    whole = set(map(_key, check_motion(take)))
    monkeypatch.setattr(pieces, "PIECE_FRAMES", 1000)
    cut = set(map(_key, check_motion(take)))
    assert {k for k in whole if k[4] != "low"} == {k for k in cut if k[4] != "low"}
    assert len(whole ^ cut) <= 0.1 * len(whole)


def test_a_finding_that_runs_over_pieces_is_one():
    """A gap of 1,100 frames (9 s) across three pieces, longer than a piece and the frames read
    around it, and a hold across the seam of two: one finding each, over its frames, as the whole
    take gives."""
    take = mt.read_take(LONG[0]) if LONG else pytest.skip("the real-file corpus (../shared/data/cmu) is absent")
    values = take.values.copy()
    (column,) = take.columns("lhumerus", ("rx",))
    values[500:900, column] = values[500, column]
    values[1200:2300, take.columns("rradius", ("rx",))[0]] = np.nan
    held = take.replace(values=values)
    whole = check_motion(held)
    old = pieces.PIECE_FRAMES
    try:
        pieces.PIECE_FRAMES = 700
        cut = check_motion(held)
    finally:
        pieces.PIECE_FRAMES = old
    for kind, joint in (("frozen", "lhumerus"), ("gap", "rradius")):
        got = [(f.first, f.last, f.severity, f.size) for f in cut if f.kind == kind and f.joints == (joint,)]
        want = [(f.first, f.last, f.severity, f.size) for f in whole if f.kind == kind and f.joints == (joint,)]
        assert got == want and len(got) == 1, (kind, got, want)


def _repeated(frames: int) -> bytes:
    """cmu/01_01.amc with its frames repeated and renumbered up to ``frames`` frames."""
    text = (DATA / "cmu" / "01_01.amc").read_bytes()
    first = re.search(rb"(?m)^1\s*$", text).start()
    blocks = re.split(rb"(?m)^\d+\s*\r?\n", text[first:])[1:]
    return text[:first] + b"".join(b"%d\r\n" % (i + 1) + blocks[i % len(blocks)] for i in range(frames))


@pytest.mark.parametrize("piece", [7, 64, 500])
def test_pieces_shorter_than_the_frames_read_around_them_see_every_frame(piece, monkeypatch):
    """Pieces of fewer frames than the 3 s read on either side (a rate of thousands of Hz has
    them): each piece is checked with the frames in reach of it, so a finding on every frame (of
    a joint of its own) comes back once per frame, and each piece sees its margin on either side."""
    take = mt.read_take(LONG[0]) if LONG else pytest.skip("the real-file corpus (../shared/data/cmu) is absent")
    take = take.crop(take.first_frame, take.first_frame + 999)
    margin = round(pieces.MARGIN_SECONDS * take.frame_rate)
    seen = []

    def every_frame(piece, begins, ends):
        seen.append((piece.first_frame, piece.last_frame))
        return [
            Finding("t", "spike", (f"j{f}",), f, f, "low", 0.0, "", "")
            for f in range(piece.first_frame, piece.last_frame + 1)
        ]

    monkeypatch.setattr(pieces, "PIECE_FRAMES", piece)
    found = pieces.check_frames(take.replace(values=take.values[:0]), [take.values], every_frame)
    assert [f.first for f in found] == list(range(take.first_frame, take.last_frame + 1))
    assert len(seen) > 1
    for (first, last), core in zip(seen, range(take.first_frame, take.last_frame + 1, piece)):
        assert first == max(core - margin, take.first_frame)
        assert last == (take.last_frame if (first, last) == seen[-1] else core + piece - 1 + margin)


def test_an_amc_read_as_it_is_checked_takes_memory_that_does_not_grow_with_it(tmp_path, monkeypatch):
    """A take four times as long takes no more memory to check (it is read a piece at a time),
    and what is found in it is what reading it whole finds."""
    if not real_files("cmu/01_01.amc"):
        pytest.skip("the real-file corpus (../shared/data/cmu) is absent")
    monkeypatch.setattr(pieces, "PIECE_FRAMES", 1000)
    peaks, found = {}, {}
    for frames in (6000, 24000):
        path = tmp_path / f"long{frames}.amc"
        path.write_bytes(_repeated(frames))
        (job,) = survey.plan([str(path)], asf=str(DATA / "cmu" / "01.asf"))
        monkeypatch.setattr(survey, "STREAM_ABOVE", 0)
        monkeypatch.setattr(survey, "READ_BYTES", 1 << 20)  # a megabyte of text at a time
        tracemalloc.start()
        streamed = survey.check_job(job)
        peaks[frames] = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        monkeypatch.setattr(survey, "STREAM_ABOVE", 1 << 60)
        whole = survey.check_job(job)
        assert streamed.frames == whole.frames == frames
        assert streamed.findings == whole.findings
        found[frames] = collections.Counter(f.kind for f in streamed.findings)
    assert peaks[24000] < 1.25 * peaks[6000], peaks
    assert found[24000]["teleport"] > found[6000]["teleport"] > 0  # the seams of the repeats, found all along


def test_takes_are_read_a_few_at_a_time_and_found_as_one_by_one(tmp_path):
    """A worker reads a few takes before it checks them: the groups keep the jobs' order, hold
    at most READ_TOGETHER takes and STREAM_ABOVE bytes in all (a larger take alone), and the
    survey finds in each take what checking it alone finds, an unreadable one among them."""
    if not real_files("hdm05/*.amc"):
        pytest.skip("the real-file corpus (../shared/data/hdm05) is absent")
    (tmp_path / "broken.amc").write_text(":DEGREES\n1\nroot 0 0\n")
    jobs = survey.plan([str(DATA / "hdm05"), str(tmp_path / "broken.amc")], asf=None)
    jobs += [dataclasses.replace(jobs[0], bytes=survey.STREAM_ABOVE - 1)] * 2  # too large to share a group
    groups = survey.reading_groups(jobs)
    assert [job for group in groups for job in group] == jobs
    assert max(map(len, groups)) == survey.READ_TOGETHER
    assert all(len(g) == 1 or sum(j.bytes for j in g) <= survey.STREAM_ABOVE for g in groups)
    assert [len(g) for g in groups[-2:]] == [1, 1]
    assert max(map(len, survey.reading_groups(jobs, workers=4))) == len(jobs) // 16  # four groups or more a worker
    checks = survey.survey(jobs, workers=1)
    assert [c.findings for c in checks] == [survey.check_job(job).findings for job in jobs]
    assert checks[len(jobs) - 3].findings[0].kind == "unreadable"
