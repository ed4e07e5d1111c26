"""Speed of writing numbers: a mean-5 filtered take (values of 16-17 digits) against the raw take
(short decimals, the same writer) and against the formatter this one replaced, in one run.

Run: python -m pytest benchmarks/bench_format.py
The take is cmu/01_01.amc repeated to about 100 MB (125,000 frames), as in bench_amc.py.  The
old formatter is csrc/format.c of commit ae1be65 (snprintf and strtod for values of 16-17
digits), built here from git with the C compiler at -O3; being that slow, it writes a tenth of
the frames, through the same chunked loop as mtcore.text.format_frames.
"""

import os
import subprocess
from itertools import groupby
from pathlib import Path

import cffi
import numpy as np
import pytest

import motiontheater as mt
import mtcore
from conftest import DATA, repeated_take

FRAMES = 125_000
FAST = dict(rounds=5, iterations=1, warmup_rounds=1)
OLD = "ae1be65"  # main when this formatter was written
ROOT = Path(__file__).resolve().parents[1]
WRITE = "write mean-5 filtered 100 MB AMC (Motion -> file)"
RAW = "write the raw 100 MB AMC (Motion -> file)"
READ = "read mean-5 filtered 100 MB AMC (file -> Motion), 1 thread"


@pytest.fixture(scope="module")
def raw(tmp_path_factory):
    if not DATA.is_dir():
        pytest.skip(f"real capture corpus not found at {DATA}")
    path = tmp_path_factory.mktemp("format") / "raw.amc"
    path.write_bytes(repeated_take(FRAMES))
    return mt.read_amc(path, mt.read_asf(DATA / "cmu" / "01.asf"))


@pytest.fixture(scope="module")
def smoothed(raw):
    return raw.replace(values=mtcore.uniform_filter1d(raw.values, 5, axis=0, mode="nearest"))


@pytest.fixture(scope="module")
def old_formatter(tmp_path_factory):
    """mt_format_frames of commit OLD, compiled from git into a shared library."""
    build = tmp_path_factory.mktemp("old")
    try:
        for name in ("format.c", "decimal.h", "mtcore.h"):
            shown = subprocess.run(["git", "-C", ROOT, "show", f"{OLD}:csrc/{name}"], capture_output=True, check=True)
            (build / name).write_bytes(shown.stdout)
        compiler = os.environ.get("CC", "cc")
        subprocess.run(
            [compiler, "-O3", "-std=c11", "-shared", "-fPIC", "format.c", "-o", "old.so", "-lm"], cwd=build, check=True
        )
    except (OSError, subprocess.CalledProcessError) as e:
        pytest.skip(f"the formatter of {OLD} could not be built from git: {e}")
    ffi = cffi.FFI()
    ffi.cdef(
        "size_t mt_format_bound(size_t, const size_t *, const size_t *, size_t);"
        "int mt_format_frames(const double *, size_t, size_t, long long, const char *const *, const size_t *,"
        " const size_t *, const size_t *, size_t, char *, size_t, size_t *);"
    )
    return ffi, ffi.dlopen(str(build / "old.so"))


def layout(motion) -> tuple[list[bytes], list[int], list[int]]:
    """Keys, column offsets and counts of the motion's joints, in column order."""
    keys, offsets, counts, column = [], [], [], 0
    for joint, dofs in groupby(motion.channels, key=lambda channel: channel[0]):
        count = len(list(dofs))
        keys.append(joint.encode())
        offsets.append(column)
        counts.append(count)
        column += count
    return keys, offsets, counts


def write_old(formatter, values: np.ndarray, keys, offsets, counts, path: Path) -> None:
    ffi, lib = formatter
    strings = [ffi.new("char[]", k) for k in keys]
    c_keys, lens = ffi.new("const char *[]", strings), ffi.new("size_t[]", [len(k) for k in keys])
    c_offsets, c_counts = ffi.new("size_t[]", offsets), ffi.new("size_t[]", counts)
    chunk, (frames, channels) = 2048, values.shape
    buf = ffi.new("char[]", lib.mt_format_bound(chunk, lens, c_counts, len(keys)))
    written = ffi.new("size_t *")
    c_values = ffi.from_buffer("double[]", values)
    with open(path, "wb") as f:
        for f0 in range(0, frames, chunk):
            n = min(chunk, frames - f0)
            args = (c_values + f0 * channels, n, channels, f0 + 1, c_keys, lens, c_offsets, c_counts, len(keys))
            assert lib.mt_format_frames(*args, buf, len(buf), written) == 0
            f.write(ffi.buffer(buf, written[0]))


def test_write_raw(benchmark, record, raw, tmp_path):
    out = tmp_path / "raw.amc"
    benchmark.pedantic(mt.write_amc, (raw, out), **FAST)
    record(WRITE, "raw take", out.stat().st_size, unit="MB")
    record(RAW, "mtcore", out.stat().st_size, unit="MB", target=f">= 1x {OLD} formatter")


def test_write_raw_old(benchmark, record, raw, old_formatter, tmp_path):
    out = tmp_path / "old.amc"
    benchmark.pedantic(write_old, (old_formatter, raw.values, *layout(raw), out), **FAST)
    record(RAW, f"{OLD} formatter", out.stat().st_size, unit="MB")


def test_write_smoothed(benchmark, record, smoothed, tmp_path):
    out = tmp_path / "smoothed.amc"
    benchmark.pedantic(mt.write_amc, (smoothed, out), **FAST)
    record(WRITE, "mtcore", out.stat().st_size, unit="MB", target=f">= 0.8x raw take, >= 5x {OLD} formatter")
    back = mt.read_amc(out, smoothed.skeleton)
    assert back.values.tobytes() == smoothed.values.tobytes()


def test_write_smoothed_old(benchmark, record, smoothed, old_formatter, tmp_path):
    out = tmp_path / "old.amc"
    tenth = np.ascontiguousarray(smoothed.values[: FRAMES // 10])
    benchmark.pedantic(write_old, (old_formatter, tenth, *layout(smoothed), out), rounds=1, iterations=1)
    record(WRITE, f"{OLD} formatter", out.stat().st_size, unit="MB")
    back = mt.read_amc(out, smoothed.skeleton)
    assert back.values.tobytes() == tenth.tobytes()


def test_write_smoothed_six_digits(benchmark, record, smoothed, tmp_path):
    """digits=6: the size of the input, as %.6g wrote it."""
    out = tmp_path / "six.amc"
    keys, offsets, counts = layout(smoothed)

    def write():
        with open(out, "wb") as f:
            mtcore.format_frames(smoothed.values, 1, keys, offsets, counts, f.write, digits=6)

    benchmark.pedantic(write, **FAST)
    record("write mean-5 filtered AMC, digits=6", "mtcore", out.stat().st_size, unit="MB")


@pytest.fixture(scope="module")
def texts(raw, smoothed, tmp_path_factory):
    folder = tmp_path_factory.mktemp("texts")
    for name, motion in (("raw", raw), ("smoothed", smoothed)):
        mt.write_amc(motion, folder / f"{name}.amc")
    return folder


@pytest.mark.parametrize("name", ["raw", "smoothed"])
def test_read(benchmark, record, raw, texts, name):
    path = texts / f"{name}.amc"
    motion = benchmark.pedantic(mt.read_amc, (path, raw.skeleton), dict(workers=1), **FAST)
    assert motion.frames == FRAMES
    record(READ, "mtcore" if name == "smoothed" else "raw take", path.stat().st_size, unit="MB")
