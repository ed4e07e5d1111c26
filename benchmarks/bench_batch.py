"""Throughput of batch filtering on about 1 GB of AMC, on one process and on two.

Run: python -m pytest benchmarks/bench_batch.py
The visible corpus (44 AMC takes, 13.7 MB) is copied 75 times (1.03 GB);
each take is read, filtered (median 5, mean 5, binomial 7) and written.  Outputs go to disk
(the test's tmp folder) and, where the machine has one, to memory
(/dev/shm): on a small virtual disk, writing 1 GB back is what limits the
first, the processing itself the second.
"""

import os
import shutil
from pathlib import Path

import pytest

from conftest import DATA
from motiontheater import Pipeline, batch

COPIES = 75


@pytest.fixture(scope="module")
def corpus(tmp_path_factory):
    if not DATA.is_dir():
        pytest.skip(f"real capture corpus not found at {DATA}")
    root = tmp_path_factory.mktemp("corpus")
    for copy in range(COPIES):
        shutil.copytree(
            DATA, root / f"copy{copy:02d}", ignore=shutil.ignore_patterns("*.npz", "*.csv", "*.bvh", "licenses", "*.md")
        )
    return root


TARGETS = {"disk": None, "memory": Path("/dev/shm")}
FILTERS = {"median 5": ("median", 5), "mean 5": ("mean", 5), "binomial 7": ("binomial", 7)}


@pytest.mark.parametrize("where", TARGETS)
@pytest.mark.parametrize("jobs", [1, 2])
@pytest.mark.parametrize("kind", FILTERS)
def test_batch_throughput(benchmark, record, corpus, tmp_path, kind, jobs, where):
    if TARGETS[where] is not None and not TARGETS[where].is_dir():
        pytest.skip(f"no {TARGETS[where]} on this machine")
    base = tmp_path if TARGETS[where] is None else Path(TARGETS[where]) / f"mt-bench-{os.getpid()}"
    name, size = FILTERS[kind]
    out = base / "out"

    def clear():  # the last round's outputs go between rounds, untimed: deleting files is not the batch's work
        shutil.rmtree(out, ignore_errors=True)

    def run():
        plan, settled = batch.plan_jobs([str(corpus)], out, Pipeline.of(name, size=size))
        summary = batch.run(plan, settled, workers=jobs, out=out)
        assert not summary.failed
        return summary

    summary = benchmark.pedantic(run, setup=clear, rounds=2, iterations=1)
    amount = sum(r.bytes for r in summary.results)
    processes = f"--jobs {jobs}"
    record(
        f"batch --{kind} {processes}, 1 GB of AMC, outputs in {where}",
        "mtcore",
        amount,
        unit="MB",
        target=f">= {100 * jobs} MB/s (100 MB/s per core)",
    )
    record(
        f"batch --{kind}, outputs in {where}: --jobs 2 vs --jobs 1",
        "mtcore" if jobs == 2 else processes,
        amount,
        unit="MB",
        target="--jobs 2 >= 1.6x --jobs 1",
    )
    # the smoothing filters against the median, whose outputs are the input's own short numbers
    for smoothing in [kind] if kind != "median 5" else [k for k in FILTERS if k != "median 5"]:
        record(
            f"batch --{smoothing} vs --median 5, {processes}, outputs in {where}",
            "mtcore" if kind == smoothing else kind,
            amount,
            unit="MB",
            target="within 20% of --median 5 (>= 0.8x)",
        )
    shutil.rmtree(base, ignore_errors=True)
