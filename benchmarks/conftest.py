"""Collects every benchmark's timing and prints the ratio table at the end of the run.

Each case (a shape, a filter, a size, a file) is measured for mtcore and for
its references in the same run; the table gives throughput and the ratios
the issues set as targets.  Ratios use each benchmark's fastest round, the
figure least disturbed by other load on a shared machine.
"""

import re
import shutil
from collections import defaultdict

import pytest

from corpus import DATA

RESULTS: dict[str, dict[str, tuple[float, float, str]]] = defaultdict(dict)
CEILING: dict[str, str] = {}  # case -> the case holding its memory-copy reference
TARGETS: dict[str, str] = {}
NOTES: list[str] = []  # measured facts that are not timings (peak memory)


def repeated_take(frames: int) -> bytes:
    """cmu/01_01.amc with its frames repeated and renumbered up to ``frames`` frames (125,000: about 100 MB)."""
    text = (DATA / "cmu" / "01_01.amc").read_bytes()
    first = re.search(rb"(?m)^1\s*$", text).start()
    blocks = re.split(rb"(?m)^\d+\s*\r?\n", text[first:])[1:]
    out = [text[:first]]
    for i in range(frames):
        out.append(b"%d\r\n" % (i + 1))
        out.append(blocks[i % len(blocks)])
    return b"".join(out)


@pytest.fixture
def record(benchmark):
    """File this test's fastest round under ``case`` as measured for ``who``
    ("mtcore", "copy" or a peer's name) over ``amount`` of ``unit`` (values or MB); or
    ``seconds``, where a test times several things in each round."""

    def _record(
        case: str,
        who: str,
        amount: float,
        ceiling: str = "",
        target: str = "",
        unit: str = "M values",
        seconds: float | None = None,
    ) -> None:
        RESULTS[case][who] = (benchmark.stats.stats.min if seconds is None else seconds, amount, unit)
        if ceiling:
            CEILING[case] = ceiling
        if target:
            TARGETS[case] = target

    return _record


def _rate(entry) -> float:
    seconds, amount, _ = entry
    return amount / seconds


def _shown(entry) -> str:
    """An entry's rate as the table shows it: in millions where its unit says so ("M values",
    "MB"), else in its own unit (hours, queries, pages); whole above 100, else three significant
    digits."""
    x = _rate(entry) / (1e6 if entry[2] == "MB" or entry[2].startswith("M ") else 1.0)
    return f"{x:.0f}" if x >= 100 else f"{x:.3g}"


def _ratio(x: float) -> str:
    """A rate against another's: two decimals below 1 (0.56x, not 0.6x, beside a target of 0.8x)."""
    return f"{x:.2f}x" if x < 1 else f"{x:.1f}x"


def _time(seconds: float) -> str:
    return f"{seconds * 1e6:.1f} us" if seconds < 1e-3 else f"{seconds * 1e3:.1f} ms"


def pytest_terminal_summary(terminalreporter):
    if not RESULTS:
        return
    write = terminalreporter.write_line
    write("")
    write("| case | mtcore | rate | vs copy | vs peers | target |")
    write("|---|---:|---:|---:|---|---|")
    for case, whos in RESULTS.items():
        if case in CEILING.values():
            entry = whos["copy"]
            write(f"| {case} | {_time(entry[0])} | {_shown(entry)} {entry[2]}/s | 100% | - | ceiling |")
            continue
        ours = whos.get("mtcore")
        if ours is None:
            continue
        ref = RESULTS.get(CEILING.get(case, ""), {}).get("copy")
        vs_copy = f"{_rate(ours) / _rate(ref):.0%}" if ref else "-"
        peers = ", ".join(f"{who} {_ratio(_rate(ours) / _rate(e))}" for who, e in whos.items() if who != "mtcore")
        write(
            f"| {case} | {_time(ours[0])} | {_shown(ours)} {ours[2]}/s | {vs_copy} | "
            f"{peers or '-'} | {TARGETS.get(case, '')} |"
        )
    for note in NOTES:
        write(note)


def amc_copies(tmp_path_factory, copies: int):
    """The corpus's AMC takes and skeletons copied ``copies`` times into a fresh folder (a
    database to time batch and check on); skips when the corpus is absent."""
    if not DATA.is_dir():
        pytest.skip(f"real capture corpus not found at {DATA}")
    root = tmp_path_factory.mktemp("corpus")
    for copy in range(copies):
        shutil.copytree(
            DATA, root / f"copy{copy:02d}", ignore=shutil.ignore_patterns("*.npz", "*.csv", "*.bvh", "licenses", "*.md")
        )
    return root
