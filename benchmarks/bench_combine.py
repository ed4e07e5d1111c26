"""Speed of the combiner on two one-hour motions against numpy and a per-frame Python loop.

Run: python -m pytest benchmarks/bench_combine.py
Two synthetic 120 Hz hours (432,000 frames x 62 channels, the CMU skeleton):
cut 1,000..400,000 scaled onto 5,000..420,000, with blend depth 10, or
with the root preserved by the thesis's rule or on the ground plane (the
thesis makes blend and preserve exclusive).  Every peer includes working
out the frame map.  The numpy peer is the same rules in whole-array numpy
(tests/twins/combine.py, with numpy Euler conversions); the Python peer is
the thesis's structure, a loop over frames and channels that works out each
frame's source and weight as it goes, run on 1/400 of the frames.
"""

import importlib
from unittest import mock

import numpy as np
import pytest

import motiontheater as mt
from conftest import DATA
from motiontheater.editing.combine import _root_offsets, combine, plan
from twins import combine as twin
from twins import rotations as euler_twin

FRAMES = 432_000
CASES = {
    "cut+scale+blend 10": dict(cut=(1_000, 400_000), scale=(5_000, 420_000), blend=10),
    "cut+scale+preserve literal": dict(cut=(1_000, 400_000), scale=(5_000, 420_000), preserve="literal"),
    "cut+scale+preserve ground": dict(cut=(1_000, 400_000), scale=(5_000, 420_000), preserve="ground"),
}


@pytest.fixture(scope="module")
def hours():
    if not DATA.is_dir():
        pytest.skip(f"real capture corpus not found at {DATA}")
    skeleton = mt.read_asf(DATA / "cmu" / "01.asf")
    rng = np.random.default_rng(0)
    old, new = (mt.Motion(skeleton, rng.standard_normal((FRAMES, 62)).cumsum(axis=0) * 0.1) for _ in range(2))
    return old, new


def output_values(old, new, options):
    return len(plan(old, new, **options).frames) * 62


@pytest.mark.parametrize("case", CASES)
def test_combine_mtcore(benchmark, record, hours, case):
    old, new = hours
    result = benchmark.pedantic(combine, (old, new), CASES[case], rounds=5, iterations=1, warmup_rounds=1)
    assert result.frames == FRAMES
    record(
        f"combine two 1-hour motions, {case}",
        "mtcore",
        output_values(old, new, CASES[case]),
        target=">= 200 M values/s, >= 3x numpy, >= 100x Python loop",
    )


def _numpy_rules(old, new, options):
    p = plan(old, new, **options)
    selected = np.ones(62, np.uint8)
    extra = {}
    if p.preserve:
        # the root's turn on numpy's Euler conversions, not the C ones
        with mock.patch.object(importlib.import_module("motiontheater.editing.combine"), "rot", euler_twin):
            rows, offsets, channels = _root_offsets(old, new, p, "y")
        extra = dict(offset_row=rows, offsets=offsets, offset_channels=channels)
    rows = (p.old_row, p.new_row, p.weight)
    return twin.combine_frames(
        old.values, new.values, *rows, next_row=p.next_row, ramp=p.ramp, selected=selected, **extra
    )


@pytest.mark.parametrize("case", CASES)
def test_combine_numpy(benchmark, record, hours, case):
    old, new = hours
    result = benchmark.pedantic(_numpy_rules, (old, new, CASES[case]), rounds=3, iterations=1)
    # the same rules, or the ratio means nothing
    ours = combine(old, new, rotation_blend="linear", **CASES[case]).values
    np.testing.assert_allclose(result, ours, rtol=0, atol=1e-9 * np.abs(ours).max())
    record(f"combine two 1-hour motions, {case}", "numpy", output_values(old, new, CASES[case]))


@pytest.mark.parametrize("case", [c for c in CASES if "ground" not in c])
def test_combine_python_loop(benchmark, record, hours, case):
    """The thesis's per-frame loop on the first 1/400 of both hours, the same rules scaled down."""
    old, new = hours
    part = FRAMES // 400
    small_old = old.replace(values=old.values[:part])
    small_new = new.replace(values=new.values[:part])
    options = dict(CASES[case], cut=(3, part - 100), scale=(12, part - 50))
    p = plan(small_old, small_new, **options)
    windows = [(b.window[0], b.window[1], b.step, b.side) for b in p.borders if b.window]
    offsets = None
    if p.preserve:
        rows, table, channels = _root_offsets(small_old, small_new, p, "y")
        first = int(p.frames[0])
        spans = [(row, first + np.flatnonzero(rows == row)) for row in range(len(table))]
        offsets = [(int(f.min()), int(f.max()), dict(zip(channels, table[row].tolist()))) for row, f in spans]
    lists = small_old.values.tolist(), small_new.values.tolist()
    selected = [1] * 62
    result = benchmark.pedantic(
        lambda: twin.python_thesis(*lists, 1, 1, options["cut"], options["scale"], windows, selected, offsets),
        rounds=3,
        iterations=1,
    )
    np.testing.assert_allclose(
        np.array(result), combine(small_old, small_new, rotation_blend="linear", **options).values, rtol=0, atol=1e-9
    )
    record(f"combine two 1-hour motions, {case}", "Python loop", len(p.frames) * 62)
