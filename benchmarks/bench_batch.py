"""Throughput of batch filtering on about 1 GB of AMC, on one process and on two.

Run: python -m pytest benchmarks/bench_batch.py
The visible corpus (44 AMC takes, 13.7 MB) is copied 75 times (1.03 GB);
each take is read, median-filtered (size 5) and written.  Outputs go to disk
(the test's tmp folder) and, where the machine has one, to memory
(/dev/shm): on a small virtual disk, writing 1 GB back is what limits the
first, the processing itself the second.
"""

import os
import shutil
from pathlib import Path

import pytest

from motiontheater import Pipeline, batch

DATA = Path(os.environ.get("MOTIONTHEATER_DATA", Path(__file__).resolve().parents[2] / "shared" / "data"))
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


@pytest.mark.parametrize("where", TARGETS)
@pytest.mark.parametrize("jobs", [1, 2])
def test_batch_throughput(benchmark, record, corpus, tmp_path, jobs, where):
    if TARGETS[where] is not None and not TARGETS[where].is_dir():
        pytest.skip(f"no {TARGETS[where]} on this machine")
    base = tmp_path if TARGETS[where] is None else Path(TARGETS[where]) / f"mt-bench-{os.getpid()}"
    runs = iter(range(100))

    def run():
        out = base / f"out{next(runs)}"
        plan, settled = batch.plan_jobs([str(corpus)], out, Pipeline.of("median", size=5))
        summary = batch.run(plan, settled, workers=jobs, out=out)
        assert not summary.failed
        return summary

    summary = benchmark.pedantic(run, rounds=2, iterations=1)
    size = sum(r.bytes for r in summary.results)
    record(
        f"batch median 5 over 1 GB of AMC, outputs in {where}",
        "mtcore" if jobs == 2 else "1 process",
        size,
        unit="MB",
        target=">= 100 MB/s per core; --jobs 2 >= 1.6x --jobs 1",
    )
    shutil.rmtree(base, ignore_errors=True)
