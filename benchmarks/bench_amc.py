"""Speed of AMC reading and writing against pandas and plain Python, in one run.

Run: python -m pytest benchmarks/bench_amc.py
The take cmu/01_01.amc is repeated to about 100 MB (125,000 frames at 120 Hz,
17 minutes); plain Python, much slower, parses a tenth of it.
"""

import subprocess
import sys
import textwrap

import numpy as np
import pytest

import motiontheater as mt
from conftest import DATA, NOTES, repeated_take

FRAMES = 125_000
SLOW = dict(rounds=3, iterations=1)
FAST = dict(rounds=5, iterations=1, warmup_rounds=1)
pd = pytest.importorskip("pandas")


@pytest.fixture(scope="module")
def skeleton():
    if not DATA.is_dir():
        pytest.skip(f"real capture corpus not found at {DATA}")
    return mt.read_asf(DATA / "cmu" / "01.asf")


@pytest.fixture(scope="module")
def big(tmp_path_factory, skeleton):
    path = tmp_path_factory.mktemp("amc") / "big.amc"
    path.write_bytes(repeated_take(FRAMES))
    return path


@pytest.fixture(scope="module")
def tenth(tmp_path_factory, skeleton):
    path = tmp_path_factory.mktemp("amc") / "tenth.amc"
    path.write_bytes(repeated_take(FRAMES // 10))
    return path


def python_parser(path, skeleton):
    """A plain Python AMC reader: split lines, float() every token."""
    columns, offset = {}, 0
    for joint in skeleton.joint_names:
        columns[joint] = offset
        offset += len(skeleton.dofs(joint))
    rows = []
    with open(path, "rb") as f:
        for line in f:
            words = line.split()
            if not words or words[0][:1] in b"#:":
                continue
            if len(words) == 1:
                row = [0.0] * offset
                rows.append(row)
                continue
            start = columns[words[0].decode()]
            row[start : start + len(words) - 1] = map(float, words[1:])
    return np.array(rows)


def python_writer(values, skeleton, out):
    columns = [(j, i, len(skeleton.dofs(j))) for i, j in enumerate(skeleton.joint_names) if skeleton.dofs(j)]
    starts = np.cumsum([0] + [len(skeleton.dofs(j)) for j in skeleton.joint_names])
    for f, row in enumerate(values.tolist(), start=1):
        out.write(f"{f}\n")
        for joint, i, n in columns:
            out.write(joint + " " + " ".join(repr(v) for v in row[starts[i] : starts[i] + n]) + "\n")


READS = {"all cores": None, "1 thread": 1}


@pytest.mark.parametrize("threads", READS)
def test_read_amc(benchmark, record, big, skeleton, threads):
    motion = benchmark.pedantic(mt.read_amc, (big, skeleton), dict(workers=READS[threads]), **FAST)
    assert motion.frames == FRAMES
    record(
        f"read 100 MB AMC (file -> Motion), {threads}",
        "mtcore",
        big.stat().st_size,
        unit="MB",
        target=">= 300 MB/s, >= 6x pandas, >= 20x plain Python",
    )


def test_pandas_read_csv(benchmark, record, big):
    """pandas' fastest reading of the same numbers: single-blank separator, C engine."""
    header = 4
    table = benchmark.pedantic(
        pd.read_csv, (big,), dict(sep=" ", header=None, names=range(7), skiprows=header, engine="c"), **SLOW
    )
    assert len(table) == FRAMES * 30
    for threads in READS:
        record(f"read 100 MB AMC (file -> Motion), {threads}", "pandas.read_csv", big.stat().st_size, unit="MB")


def test_python_reader(benchmark, record, tenth, skeleton):
    values = benchmark.pedantic(python_parser, (tenth, skeleton), rounds=1, iterations=1)
    np.testing.assert_array_equal(values, mt.read_amc(tenth, skeleton).values)
    for threads in READS:
        record(f"read 100 MB AMC (file -> Motion), {threads}", "plain Python", tenth.stat().st_size, unit="MB")


def test_write_amc(benchmark, record, big, skeleton, tmp_path):
    motion = mt.read_amc(big, skeleton)
    out = tmp_path / "out.amc"
    benchmark.pedantic(mt.write_amc, (motion, out), **FAST)
    record(
        "write 100 MB AMC (Motion -> file)",
        "mtcore",
        out.stat().st_size,
        unit="MB",
        target=">= 50 MB/s, >= 5x plain Python",
    )


def test_python_writer(benchmark, record, tenth, skeleton, tmp_path):
    values = mt.read_amc(tenth, skeleton).values
    out = tmp_path / "py.amc"

    def write():
        with open(out, "w") as f:
            python_writer(values, skeleton, f)

    benchmark.pedantic(write, rounds=1, iterations=1)
    record("write 100 MB AMC (Motion -> file)", "plain Python", out.stat().st_size, unit="MB")


def test_peak_memory_of_reading(benchmark, big):
    """Peak resident memory of read_amc in a fresh process, against 2 x values + file size."""
    script = textwrap.dedent(f"""
        import re, motiontheater as mt
        def rss(key):
            return int(re.search(key + r":\\s+(\\d+)", open("/proc/self/status").read()).group(1)) * 1024
        skeleton = mt.read_asf({str(DATA / "cmu" / "01.asf")!r})
        base = rss("VmRSS")
        motion = mt.read_amc({str(big)!r}, skeleton)
        print(rss("VmHWM") - base, motion.values.nbytes)
    """)
    done = benchmark.pedantic(
        subprocess.run,
        ([sys.executable, "-c", script],),
        dict(capture_output=True, text=True, check=True),
        rounds=1,
        iterations=1,
    )
    peak, nbytes = map(int, done.stdout.split())
    size = big.stat().st_size
    NOTES.append(
        f"Peak memory of read_amc on {size / 1e6:.0f} MB ({FRAMES} frames): {peak / 1e6:.0f} MB above the "
        f"interpreter = {peak / (2 * nbytes + size):.2f} x (2 x values {nbytes / 1e6:.0f} MB + file); target < 1"
    )
