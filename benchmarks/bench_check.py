"""Throughput of the take check against batch filtering, on one process, in the same run.

Run: python -m pytest benchmarks/bench_check.py
The visible AMC corpus (44 takes, 13.7 MB) is copied 10 times (137 MB); each round checks every
take (``motiontheater check``'s survey: read, the C pass, the findings) and filters every take
with ``batch --median 5`` (read, filter, write to memory where the machine has /dev/shm), one
after the other.  The issue's target: checking costs little beyond reading, >= 150 MB of AMC per
second per core and >= 0.8x ``batch --median 5``.
"""

import os
import shutil
import time
from pathlib import Path

import pytest

from conftest import amc_copies
from motiontheater import Pipeline
from motiontheater.databases import batch, survey

COPIES = 10
ROUNDS = 5


@pytest.fixture(scope="module")
def corpus(tmp_path_factory):
    return amc_copies(tmp_path_factory, COPIES)


def test_check_throughput(benchmark, record, corpus, tmp_path):
    memory = Path("/dev/shm")
    out = (memory / f"mt-bench-check-{os.getpid()}" if memory.is_dir() else tmp_path) / "out"
    times = {"check": [], "median 5": []}
    amounts = {}

    def run_round():
        start = time.perf_counter()
        jobs = survey.plan([str(corpus)])
        checks = survey.survey(jobs, workers=1)
        times["check"].append(time.perf_counter() - start)
        assert not [c for c in checks if c.findings and c.findings[0].kind == "unreadable"]
        amounts["check"] = sum(c.bytes for c in checks)
        shutil.rmtree(out, ignore_errors=True)
        start = time.perf_counter()
        plan, settled = batch.plan_jobs([str(corpus)], out, Pipeline.of("median", size=5))
        summary = batch.run(plan, settled, workers=1, out=out)
        times["median 5"].append(time.perf_counter() - start)
        assert not summary.failed
        amounts["median 5"] = sum(r.bytes for r in summary.results)
        shutil.rmtree(out, ignore_errors=True)

    benchmark.pedantic(run_round, rounds=ROUNDS, iterations=1)
    best = {key: min(seconds) for key, seconds in times.items()}
    record("check, 137 MB of AMC, --jobs 1", "mtcore", amounts["check"], unit="MB",
           target=">= 150 MB/s (per core)", seconds=best["check"])  # fmt: skip
    for who in ("check", "median 5"):
        record("check vs batch --median 5, --jobs 1", "mtcore" if who == "check" else who, amounts[who], unit="MB",
               target=">= 0.8x batch --median 5", seconds=best[who])  # fmt: skip
    shutil.rmtree(out.parent, ignore_errors=True)
