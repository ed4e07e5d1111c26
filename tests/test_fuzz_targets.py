"""The fuzz harness (fuzz/fuzz_scanners.py): its seeds and every saved finding replayed through
each target, and a short coverage-guided run of each (seconds; .ci/sanitize runs it sanitized)."""

import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import NO_SOURCE, SOURCE

FUZZ = SOURCE / "fuzz"
if not (FUZZ / "fuzz_scanners.py").is_file():
    pytest.skip(NO_SOURCE, allow_module_level=True)
spec = importlib.util.spec_from_file_location("fuzz_scanners", FUZZ / "fuzz_scanners.py")
harness = importlib.util.module_from_spec(spec)
spec.loader.exec_module(harness)


def findings(target: str) -> list[Path]:
    """Inputs that once failed (fuzz/regressions/TARGET/), kept so that they never fail again."""
    folder = FUZZ / "regressions" / target
    return sorted(folder.iterdir()) if folder.is_dir() else []


@pytest.mark.parametrize("target", sorted(harness.TARGETS))
def test_seeds_and_findings_give_a_result_or_a_value_error(target):
    run = harness.TARGETS[target]
    inputs = harness.seeds(target) + [p.read_bytes() for p in findings(target)]
    for data in inputs:
        run(data)
        for cut in (1, len(data) // 2, len(data) - 1):  # and truncated anywhere
            run(data[:cut])


@pytest.mark.parametrize("target", sorted(harness.TARGETS))
def test_a_short_coverage_guided_run(target, tmp_path):
    pytest.importorskip("atheris")
    corpus = tmp_path / "corpus"
    corpus.mkdir()
    for i, seed in enumerate(harness.seeds(target)[:3]):
        (corpus / str(i)).write_bytes(seed)
    done = subprocess.run(
        [sys.executable, str(FUZZ / "fuzz_scanners.py"), target, "-runs=3000", "-max_total_time=20",
         f"-artifact_prefix={tmp_path}/", str(corpus)],
        capture_output=True, text=True, timeout=300, check=False, env=os.environ,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr[-3000:]
    assert "Done" in done.stderr
