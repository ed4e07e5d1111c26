"""Throughput of batch filtering on about 1 GB of AMC, on one process and on two.

Run: python -m pytest benchmarks/bench_batch.py
The visible corpus (44 AMC takes, 13.7 MB) is copied 75 times (1.03 GB);
each take is read, filtered (median 5, mean 5, binomial 7) and written, on one process and on
two, each of the six in turn in each of three rounds.  Outputs go to disk
(the test's tmp folder) and, where the machine has one, to memory
(/dev/shm): on a small virtual disk, writing 1 GB back is what limits the
first, the processing itself the second.
"""

import os
import shutil
import time
from pathlib import Path

import pytest

from conftest import amc_copies
from motiontheater import Pipeline
from motiontheater.databases import batch

COPIES = 75


@pytest.fixture(scope="module")
def corpus(tmp_path_factory):
    return amc_copies(tmp_path_factory, COPIES)


TARGETS = {"disk": None, "memory": Path("/dev/shm")}
FILTERS = {"median 5": ("median", 5), "mean 5": ("mean", 5), "binomial 7": ("binomial", 7)}
JOBS = (1, 2)
ROUNDS = 3


@pytest.mark.parametrize("where", TARGETS)
def test_batch_throughput(benchmark, record, corpus, tmp_path, where):
    """Every filter on one process and on two, one after the other in each round, so that the
    ratios compare runs minutes apart at most on a machine whose speed drifts; each figure is
    its fastest round."""
    if TARGETS[where] is not None and not TARGETS[where].is_dir():
        pytest.skip(f"no {TARGETS[where]} on this machine")
    base = tmp_path if TARGETS[where] is None else Path(TARGETS[where]) / f"mt-bench-{os.getpid()}"
    out = base / "out"
    times: dict[tuple[str, int], list[float]] = {(kind, jobs): [] for kind in FILTERS for jobs in JOBS}
    amounts = {}

    def run_round():
        for (kind, jobs), seconds in times.items():
            shutil.rmtree(out, ignore_errors=True)  # untimed: deleting files is not the batch's work
            os.sync()  # and each run starts with no other run's writes still going to the disk
            name, size = FILTERS[kind]
            start = time.perf_counter()
            plan, settled = batch.plan_jobs([str(corpus)], out, Pipeline.of(name, size=size))
            summary = batch.run(plan, settled, workers=jobs, out=out)
            seconds.append(time.perf_counter() - start)
            assert not summary.failed
            amounts[kind, jobs] = sum(r.bytes for r in summary.results)
        shutil.rmtree(out, ignore_errors=True)

    benchmark.pedantic(run_round, rounds=ROUNDS, iterations=1)
    best = {key: min(seconds) for key, seconds in times.items()}
    for (kind, jobs), seconds in best.items():
        amount = amounts[kind, jobs]
        processes = f"--jobs {jobs}"
        record(
            f"batch --{kind} {processes}, 1 GB of AMC, outputs in {where}",
            "mtcore",
            amount,
            unit="MB",
            target=f">= {100 * jobs} MB/s (100 MB/s per core)",
            seconds=seconds,
        )
        record(
            f"batch --{kind}, outputs in {where}: --jobs 2 vs --jobs 1",
            "mtcore" if jobs == 2 else processes,
            amount,
            unit="MB",
            target="--jobs 2 >= 1.6x --jobs 1",
            seconds=seconds,
        )
        if kind != "median 5":  # the smoothing filters against the median, whose outputs are the input's own numbers
            for who, key in (("mtcore", (kind, jobs)), ("median 5", ("median 5", jobs))):
                record(
                    f"batch --{kind} vs --median 5, {processes}, outputs in {where}",
                    who,
                    amounts[key],
                    unit="MB",
                    target="within 20% of --median 5 (>= 0.8x)",
                    seconds=best[key],
                )
    shutil.rmtree(base, ignore_errors=True)
