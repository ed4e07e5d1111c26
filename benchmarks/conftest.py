"""Collects every benchmark's timing and prints the ratio table at the end of the run.

Each case (a shape, a filter, a size, an output style) is measured for mtcore
and for its references in the same run; the table gives throughput and the
ratios the issues set as targets.  Ratios use each benchmark's fastest round,
the figure least disturbed by other load on a shared machine.
"""

from collections import defaultdict

import pytest

RESULTS: dict[str, dict[str, tuple[float, int]]] = defaultdict(dict)
CEILING: dict[str, str] = {}  # case -> the case holding its memory-copy reference
TARGETS: dict[str, str] = {}


@pytest.fixture
def record(benchmark):
    """File this test's fastest round under ``case`` as measured for ``who``
    ("mtcore", "scipy" or "copy") over ``values`` values."""

    def _record(case: str, who: str, values: int, ceiling: str = "", target: str = "") -> None:
        RESULTS[case][who] = (benchmark.stats.stats.min, values)
        if ceiling:
            CEILING[case] = ceiling
        if target:
            TARGETS[case] = target

    return _record


def _rate(entry):
    seconds, values = entry
    return values / seconds


def pytest_terminal_summary(terminalreporter):
    if not RESULTS:
        return
    write = terminalreporter.write_line
    write("")
    write("| case | mtcore | M values/s | vs copy | vs scipy | target |")
    write("|---|---:|---:|---:|---:|---|")
    for case, whos in RESULTS.items():
        if case in CEILING.values():
            seconds, values = whos["copy"]
            write(f"| {case} | {seconds * 1e3:.1f} ms | {values / seconds / 1e6:.0f} | 100% | - | ceiling |")
            continue
        ours = whos.get("mtcore")
        if ours is None:
            continue
        ref = RESULTS.get(CEILING.get(case, ""), {}).get("copy")
        sci = whos.get("scipy")
        t = ours[0]
        time_text = f"{t * 1e6:.1f} us" if t < 1e-3 else f"{t * 1e3:.1f} ms"
        vs_copy = f"{_rate(ours) / _rate(ref):.0%}" if ref else "-"
        vs_scipy = f"{sci[0] / t:.0f}x" if sci else "-"
        write(
            f"| {case} | {time_text} | {_rate(ours) / 1e6:.0f} | {vs_copy} | {vs_scipy} | {TARGETS.get(case, '')} |"
        )
