"""Speed of numbers in and out: writing a mean-5 filtered take (values of 16-17 digits) against
the raw take (short decimals, the same writer) and against the formatter this one replaced;
scanning both takes against the scanner this one replaced; all in one run.

Run: python -m pytest benchmarks/bench_format.py
The take is cmu/01_01.amc repeated to about 100 MB (125,000 frames), as in bench_amc.py.  The
old formatter and scanner are csrc/format.c and scan.c of commit ae1be65 (snprintf and strtod
for values of 16-17 digits), built here from git with the C compiler at -O3 and called with
the same arguments; the old formatter, that slow there, writes a tenth of the filtered frames.
"""

import os
import re
import subprocess
from itertools import groupby
from pathlib import Path

import cffi
import numpy as np
import pytest

import motiontheater as mt
import mtcore
from conftest import DATA, NOTES, repeated_take
from mtcore._mtcore import ffi, lib
from mtcore.text import number_code, number_codes

FRAMES = 125_000
FAST = dict(rounds=5, iterations=1, warmup_rounds=1)
OLD = "ae1be65"  # main when this formatter and scanner were written
ROOT = Path(__file__).resolve().parents[1]
WRITE = "write mean-5 filtered 100 MB AMC (Motion -> file)"
RAW = "write the raw 100 MB AMC (Motion -> file)"
SCAN = "scan {} 100 MB AMC frame text, 1 thread"
CODE = "mt_format_frames of {} 100 MB AMC (in memory): the best code vs each code by name"


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
def texts(raw, smoothed, tmp_path_factory):
    folder = tmp_path_factory.mktemp("texts")
    for name, motion in (("raw", raw), ("smoothed", smoothed)):
        mt.write_amc(motion, folder / f"{name}.amc")
    return folder


@pytest.fixture(scope="module")
def old(tmp_path_factory):
    """The C formatter and scanner of commit OLD, compiled from git into a shared library."""
    build = tmp_path_factory.mktemp("old")
    try:
        for name in ("format.c", "scan.c", "decimal.h", "mtcore.h"):
            shown = subprocess.run(["git", "-C", ROOT, "show", f"{OLD}:csrc/{name}"], capture_output=True, check=True)
            (build / name).write_bytes(shown.stdout)
        command = [os.environ.get("CC", "cc"), "-O3", "-std=c11", "-shared", "-fPIC", "format.c", "scan.c"]
        subprocess.run([*command, "-o", "old.so", "-lm"], cwd=build, check=True)
    except (OSError, subprocess.CalledProcessError) as e:
        pytest.skip(f"the formatter and scanner of {OLD} could not be built from git: {e}")
    old_ffi = cffi.FFI()
    old_ffi.cdef(
        "struct mt_scan_report { size_t frames; long long first_frame; size_t line; size_t offset; long long key;"
        " long long found; long long expected; };"
        "int mt_scan_frames(const char *, size_t, const char *const *, const size_t *, const size_t *,"
        " const size_t *, size_t, double *, size_t, size_t, struct mt_scan_report *);"
        "size_t mt_format_bound(size_t, const size_t *, const size_t *, size_t);"
        "int mt_format_frames(const double *, size_t, size_t, long long, const char *const *, const size_t *,"
        " const size_t *, const size_t *, size_t, char *, size_t, size_t *);"
    )
    return old_ffi, old_ffi.dlopen(str(build / "old.so"))


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


def key_table(c_ffi, keys, offsets, counts) -> list:
    """C arrays of keys, their lengths, offsets and counts; then the strings they point to, kept alive."""
    strings = [c_ffi.new("char[]", k) for k in keys]
    sizes = [c_ffi.new("size_t[]", v) for v in ([len(k) for k in keys], offsets, counts)]
    return [c_ffi.new("const char *[]", strings), *sizes, len(keys), strings]


def write_old(library, values: np.ndarray, keys, offsets, counts, path: Path) -> None:
    """The old mt_format_frames over values, in the chunks of mtcore.text.format_frames."""
    old_ffi, old_lib = library
    *table, _ = key_table(old_ffi, keys, offsets, counts)
    chunk, (frames, channels) = 2048, values.shape
    buf = old_ffi.new("char[]", old_lib.mt_format_bound(chunk, table[1], table[3], table[4]))
    written = old_ffi.new("size_t *")
    c_values = old_ffi.from_buffer("double[]", values)
    with open(path, "wb") as f:
        for f0 in range(0, frames, chunk):
            n = min(chunk, frames - f0)
            status = old_lib.mt_format_frames(
                c_values + f0 * channels, n, channels, f0 + 1, *table, buf, len(buf), written
            )
            assert status == 0
            f.write(old_ffi.buffer(buf, written[0]))


def scan(library, text: bytes, keys, offsets, counts, channels: int, frames: int) -> np.ndarray:
    """mt_scan_frames of a library (this build's or the old one) over frame text, in one call."""
    c_ffi, c_lib = library
    *table, _ = key_table(c_ffi, keys, offsets, counts)
    values = np.empty((frames, channels))
    report = c_ffi.new("struct mt_scan_report *")
    c_values = c_ffi.from_buffer("double[]", values)
    assert c_lib.mt_scan_frames(text, len(text), *table, c_values, frames, channels, report) == 0
    assert report.frames == frames
    return values


def test_write_raw(benchmark, record, raw, tmp_path):
    out = tmp_path / "raw.amc"
    # its values as a copy: a motion written back unchanged would be its file copied, not formatted
    formatted = raw.replace(values=raw.values.copy())
    benchmark.pedantic(mt.write_amc, (formatted, out), **FAST)
    assert out.read_bytes() == Path(raw.origin.file.path).read_bytes()  # formatted as found
    record(WRITE, "raw take", out.stat().st_size, unit="MB")
    record(RAW, "mtcore", out.stat().st_size, unit="MB", target=f">= 1x {OLD} formatter")


def test_write_raw_old(benchmark, record, raw, old, tmp_path):
    out = tmp_path / "old.amc"
    benchmark.pedantic(write_old, (old, raw.values, *layout(raw), out), **FAST)
    record(RAW, f"{OLD} formatter", out.stat().st_size, unit="MB")


def test_write_smoothed(benchmark, record, smoothed, tmp_path):
    out = tmp_path / "smoothed.amc"
    benchmark.pedantic(mt.write_amc, (smoothed, out), **FAST)
    record(WRITE, "mtcore", out.stat().st_size, unit="MB", target=f">= 0.8x raw take, >= 5x {OLD} formatter")
    assert mt.read_amc(out, smoothed.skeleton).values.tobytes() == smoothed.values.tobytes()


def test_write_smoothed_old(benchmark, record, smoothed, old, tmp_path):
    out = tmp_path / "old.amc"
    tenth = np.ascontiguousarray(smoothed.values[: FRAMES // 10])
    benchmark.pedantic(write_old, (old, tenth, *layout(smoothed), out), rounds=1, iterations=1)
    record(WRITE, f"{OLD} formatter", out.stat().st_size, unit="MB")
    assert mt.read_amc(out, smoothed.skeleton).values.tobytes() == tenth.tobytes()


def test_write_smoothed_six_digits(benchmark, record, smoothed, tmp_path):
    """digits=6: files the size of the input, as %.6g wrote it."""
    out = tmp_path / "six.amc"
    keys, offsets, counts = layout(smoothed)

    def write():
        with open(out, "wb") as f:
            mtcore.format_frames(smoothed.values, 1, keys, offsets, counts, f.write, digits=6)

    benchmark.pedantic(write, **FAST)
    record("write mean-5 filtered 100 MB AMC, digits=6", "mtcore", out.stat().st_size, unit="MB")


@pytest.mark.parametrize("who", ["mtcore", f"{OLD} scanner"])
@pytest.mark.parametrize("name", ["raw", "smoothed"])
def test_scan(benchmark, record, raw, texts, old, name, who):
    """The C scanners alone on the frame text (no header, no Python reader around them)."""
    data = (texts / f"{name}.amc").read_bytes()
    body = data[re.search(rb"(?m)^1\s*$", data).start() :]
    library = (ffi, lib) if who == "mtcore" else old
    values = benchmark.pedantic(scan, (library, body, *layout(raw), raw.values.shape[1], FRAMES), **FAST)
    assert values.tobytes() == mt.read_amc(texts / f"{name}.amc", raw.skeleton).values.tobytes()
    case = SCAN.format("the raw" if name == "raw" else "a mean-5 filtered")
    record(case, who, len(body), unit="MB", target=f">= 1x {OLD} scanner" if who == "mtcore" else "")


def format_in_memory(values: np.ndarray, keys, offsets, counts, code: int) -> int:
    """mt_format_frames over values in the chunks of mtcore.text.format_frames, into one reused
    buffer (no file), the shortest texts by `code` (enum mt_number_code, see mtcore.h)."""
    *table, _ = key_table(ffi, keys, offsets, counts)
    style = ffi.new("struct mt_format_style *", [0, 2, lib.MT_NEWLINE_LF, lib.MT_NEWLINE_LF])
    chunk, (frames, channels) = 256, values.shape
    buf = ffi.new("char[]", lib.mt_format_bound(chunk, table[1], table[3], table[4], style))
    written, total = ffi.new("size_t *"), 0
    c_values = ffi.from_buffer("double[]", values)
    for f0 in range(0, frames, chunk):
        n = min(chunk, frames - f0)
        status = lib.mt_format_frames(
            c_values + f0 * channels, n, channels, f0 + 1, *table, style, code, buf, len(buf), written
        )
        assert status == lib.MT_OK
        total += written[0]
    return total


# each code (enum mt_number_code) and its name in the table
CODES = {"best": (lib.MT_NUMBER_CODE_BEST, "mtcore"), "avx512": (lib.MT_NUMBER_CODE_AVX512, "AVX-512 code"),
         "avx2": (lib.MT_NUMBER_CODE_AVX2, "AVX2 code"), "portable": (lib.MT_NUMBER_CODE_PORTABLE, "portable code")}  # fmt: skip


@pytest.mark.parametrize("code", list(CODES))
@pytest.mark.parametrize("name", ["raw", "smoothed"])
def test_format_code(benchmark, record, raw, smoothed, name, code):
    """The formatter alone, the code it takes here (number_code()) against each code by
    name, on the same values; a code this processor does not run is skipped."""
    values = raw.values if name == "raw" else smoothed.values
    c_code, who = CODES[code]
    if not lib.mt_number_code_runs(c_code):
        pytest.skip(f"this processor does not run the {who} (it runs {', '.join(number_codes())})")
    size = benchmark.pedantic(format_in_memory, (values, *layout(raw), c_code), **FAST)
    case = CODE.format("the raw" if name == "raw" else "a mean-5 filtered")
    record(case, who, size, unit="MB")
    named = f"{who} ({number_code()})" if code == "best" else who
    NOTES.append(f"{case}: {named} {benchmark.stats.stats.min / values.size * 1e9:.1f} ns a value (fastest round)")
