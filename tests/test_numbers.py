"""Numbers in and out: the C writer against Python's repr and %g, the C reader against float(),
every bit pattern class, the grammar, the locale, frame numbers and the buffer bounds.

Python's repr, '%.Ng' and float() are the slow twins: correctly rounded, locale-free.
"""

import functools
import io
import math
import platform
import re
import struct
import subprocess
import sys
from decimal import Decimal, localcontext

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import motiontheater as mt
from conftest import NO_SOURCE, SOURCE
from mtcore._mtcore import ffi, lib
from mtcore.errors import NumberError, SequenceError
from mtcore.text import (
    FRAME_MAX,
    format_frames,
    format_number,
    format_table,
    number_code,
    number_codes,
    parse_number,
    scan_frames,
    scan_table,
    text_style,
)

# ---- twins ---------------------------------------------------------------------------------


def from_bits(bits: int) -> float:
    return struct.unpack("<d", struct.pack("<Q", bits))[0]


def bits_of(x: float) -> int:
    return struct.unpack("<Q", struct.pack("<d", x))[0]


def pad_exponent(text: str, exponent_digits: int) -> str:
    return re.sub(r"e([+-])(\d+)", lambda m: f"e{m[1]}{int(m[2]):0{exponent_digits}d}", text)


def repr_text(x: float, exponent_digits: int = 2) -> str:
    """What the writer must write by default: repr's digits and layout, without a trailing '.0'."""
    if math.isnan(x):
        return "-nan" if math.copysign(1.0, x) < 0 else "nan"
    return pad_exponent(repr(x).removesuffix(".0"), exponent_digits)


def g_text(x: float, digits: int, exponent_digits: int = 2) -> str:
    """What the writer must write with digits=N: C's %.Ng, correctly rounded (Python's own)."""
    return pad_exponent(f"{x:.{digits}g}", exponent_digits)


def written(values, **style) -> list[str]:
    """The numbers of a (rows, columns) array as format_table writes them."""
    out: list[bytes] = []
    format_table(np.asarray(values, dtype=np.float64).reshape(-1, 1), out.append, **style)
    return b"".join(out).decode("ascii").split(style.get("newline", b"\n").decode())[:-1]


def read_back(tokens: list[str]) -> np.ndarray:
    """The tokens read by the frame-text scanner (its inlined fast path and the general one)."""
    return scan_table(("\n".join(tokens) + "\n").encode("ascii"), len(tokens), 1)[:, 0]


def assert_same_bits(got, want, what):
    got, want = np.asarray(got, dtype=np.float64), np.asarray(want, dtype=np.float64)
    bad = np.flatnonzero(got.view(np.uint64) != want.view(np.uint64))
    assert bad.size == 0, [(what[i], got[i], want[i]) for i in bad[:5]]


def check_writes_repr(values, exponent_digits: int = 2) -> None:
    """Every value is written as repr's digits, and reads back bit for bit (NaN: its sign)."""
    values = [float(v) for v in values]
    texts = written(values, exponent_digits=exponent_digits)
    want = [repr_text(x, exponent_digits) for x in values]
    bad = [(x.hex(), t, w) for x, t, w in zip(values, texts, want) if t != w]
    assert not bad, bad[:5]
    assert all(len(t) <= lib.MT_NUMBER_MAX for t in texts)
    finite = [i for i, x in enumerate(values) if not math.isnan(x)]
    assert_same_bits(read_back([texts[i] for i in finite]), [values[i] for i in finite], [texts[i] for i in finite])
    assert [format_number(x, exponent_digits=exponent_digits) for x in values[:50]] == want[:50]


# ---- writing ---------------------------------------------------------------------------------


@given(st.integers(0, 2**64 - 1))
@settings(max_examples=3000, deadline=None)
def test_every_bit_pattern_is_written_as_repr(bits):
    x = from_bits(bits)
    text = format_number(x)
    assert text == repr_text(x)
    if not math.isnan(x):
        assert bits_of(parse_number(text)) == bits
    else:
        assert math.isnan(parse_number(text)) and math.copysign(1, parse_number(text)) == math.copysign(1, x)


def test_random_bit_patterns_in_bulk(rng):
    check_writes_repr([from_bits(int(b)) for b in rng.integers(0, 2**63, 200_000, dtype=np.uint64)])


def test_every_binary_exponent(rng):
    """Each of the 2047 exponents, with the smallest, largest and random significands and the
    neighbours of each power of two (where the gap below is half the gap above)."""
    values = []
    for biased in range(2047):
        for mantissa in (0, 1, 2, 2**52 - 1, *rng.integers(0, 2**52, 4).tolist()):
            x = from_bits((biased << 52) | int(mantissa))
            values += [x, -x]
        if 0 < biased < 2046:
            power = from_bits(biased << 52)
            values += [math.nextafter(power, 0), math.nextafter(power, math.inf)]
    check_writes_repr(values)


def test_small_and_full_significands_at_every_exponent():
    """c 2^q for the smallest and the largest significands c at every binary exponent q: where
    the interval's ends and middle fall exactly on decimals (integers, halves, small multiples of
    powers of two), the cases the shortest writer settles by exact tests rather than its product."""
    values = [math.ldexp(c, q) for q in range(-1074, 972) for c in (*range(1, 41), *range(2**53 - 40, 2**53))]
    check_writes_repr([v for v in values if 0 < v < math.inf])


def test_subnormals(rng):
    smallest = [from_bits(b) for b in range(1, 20_000)]
    check_writes_repr(smallest + [from_bits(int(b)) for b in rng.integers(1, 2**52, 20_000)])


def test_ties_near_powers_of_two():
    """2**-24 lies exactly between 5.960464477539062e-08 and ...063e-08; the lower one reads back
    as another double (the gap below a power of two is half the gap above): repr writes 063, and
    so must we, with no extra digit.  The same for every power of two where it happens."""
    assert format_number(2.0**-24) == "5.960464477539063e-08"
    ties = []
    for e in range(-1074, 1024):
        x = math.ldexp(1.0, e)
        exact = Decimal(x)
        shortest = repr(x)
        if len(exact.as_tuple().digits) == len(Decimal(shortest).normalize().as_tuple().digits) + 1:
            ties.append(x)
    assert 2.0**-24 in ties
    check_writes_repr(ties + [2.0**e for e in range(-1074, 1024)])


def test_short_decimals_of_every_magnitude(rng):
    """Mocap-like short decimals (and what the reader's fast path covers) from 1e-320 to 1e300."""
    wide = rng.standard_normal(50_000) * 10.0 ** rng.integers(-320, 300, 50_000)
    scale = 10.0 ** rng.integers(0, 7, 50_000)
    short = np.round(rng.uniform(-400, 400, 50_000) * scale) / scale
    check_writes_repr(np.concatenate([wide, short, [0.0, -0.0, np.inf, -np.inf, np.nan, -np.nan, 1e16, 1e-5]]))


@pytest.mark.parametrize("exponent_digits", [1, 2, 3])
def test_exponent_digits(rng, exponent_digits):
    values = rng.standard_normal(5000) * 10.0 ** rng.integers(-320, 300, 5000)
    check_writes_repr(values, exponent_digits)
    assert (
        format_number(1.23246e-13, exponent_digits=exponent_digits)
        == ["1.23246e-13", "1.23246e-13", "1.23246e-013"][exponent_digits - 1]
    )
    assert format_number(1e-5, exponent_digits=exponent_digits) == ["1e-5", "1e-05", "1e-005"][exponent_digits - 1]
    assert format_number(1e300, exponent_digits=exponent_digits) == "1e+300"


@pytest.mark.parametrize("digits", range(1, 18))
def test_digits_are_correctly_rounded(rng, digits):
    """digits=N gives C's %.Ng: correctly rounded to N digits, ties to even, trailing zeros dropped."""
    patterns = [from_bits(int(b)) for b in rng.integers(0, 2**63, 20_000, dtype=np.uint64)]
    mocap = (rng.uniform(-400, 400, 5000) / 7).tolist()
    # exact ties at N digits: dyadic values with N + 1 significant digits ending in 5
    ties = [m / 2**j for j in range(1, 12) for m in range(1, 4000, 2)]
    # either side of each power of ten, where the decimal exponent is first guessed one too low
    decades = [
        y for e in range(-323, 309) for y in (10.0**e, math.nextafter(10.0**e, 0), math.nextafter(10.0**e, 1e309))
    ]
    values = [x for x in patterns + mocap + ties + decades if math.isfinite(x) and x != 0]
    values += [0.0, -0.0, 9.5, 0.95, 99.5, 9.9999999999999999e22, 5e-324, 1.7976931348623157e308]
    texts = written(values, digits=digits)
    bad = [(x.hex(), t, g_text(x, digits)) for x, t in zip(values, texts) if t != g_text(x, digits)]
    assert not bad, bad[:5]
    assert all(len(t) <= lib.MT_NUMBER_MAX for t in texts)
    assert written([np.inf, -np.inf, np.nan, -np.nan], digits=digits) == ["inf", "-inf", "nan", "-nan"]
    assert format_number(1.23246e-13, digits=digits, exponent_digits=3) == g_text(1.23246e-13, digits, 3)


def test_seventeen_digits_always_read_back(rng):
    values = [from_bits(int(b)) for b in rng.integers(0, 0x7FF0000000000000, 20_000, dtype=np.uint64)]
    assert_same_bits(read_back(written(values, digits=17)), values, values)


def c_text(function: str, values: np.ndarray, code: int, exponent_digits: int = 2, **frames) -> bytes:
    """mt_format_table or mt_format_frames (keys a, b, ... of `counts` columns) called directly, the
    shortest texts by `code` (enum mt_number_code), which the processor must run."""
    values = np.ascontiguousarray(values, dtype=np.float64)
    rows, columns = values.shape
    style = ffi.new("struct mt_format_style *", [0, exponent_digits, lib.MT_NEWLINE_LF, lib.MT_NEWLINE_CRLF])
    written = ffi.new("size_t *")
    c_values = ffi.from_buffer("double[]", values)
    if function == "table":
        cap = lib.mt_format_table_bound(rows, columns, style)
        buf = ffi.new("char[]", cap)
        assert lib.mt_format_table(c_values, rows, columns, style, code, buf, cap, written) == lib.MT_OK
    else:
        counts = frames["counts"]
        keys = [ffi.new("char[]", bytes([97 + k % 26]) * (1 + k // 26)) for k in range(len(counts))]
        key_lens = ffi.new("size_t[]", [len(ffi.string(k)) for k in keys])
        offsets = ffi.new("size_t[]", [sum(counts[:k]) for k in range(len(counts))][::-1])  # lines in reverse
        c_counts = ffi.new("size_t[]", counts[::-1])
        cap = lib.mt_format_bound(rows, key_lens, c_counts, len(keys), style)
        buf = ffi.new("char[]", cap)
        status = lib.mt_format_frames(
            c_values, rows, columns, 3, ffi.new("const char *[]", keys), key_lens, offsets, c_counts, len(keys),
            style, code, buf, cap, written,
        )  # fmt: skip
        assert status == lib.MT_OK
    return ffi.buffer(buf, written[0])[:]


def vector_cases(rng) -> list[np.ndarray]:
    """Values for the vector code: every class of bits, mocap-like values raw and smoothed (mostly 16
    and 17 digits), every decimal exponent of the plain and the exponent forms, powers of two, subnormals."""
    patterns = rng.integers(0, 2**64, 100_000, dtype=np.uint64).view(np.float64)
    magnitudes = rng.standard_normal(50_000) * 10.0 ** rng.integers(-8, 20, 50_000)
    short = np.round(rng.uniform(-400, 400, 50_000) * 1e4) / 1e4
    smoothed = np.convolve(short, np.ones(5) / 5, mode="same")
    subnormals = rng.integers(1, 2**52, 2_000, dtype=np.uint64) | rng.choice([0, 2**63], 2_000).astype(np.uint64)
    edges = [0.0, -0.0, np.inf, -np.inf, np.nan, -np.nan, 5e-324, 2.2250738585072014e-308, 1.7976931348623157e308]
    near = [(10.0**e, math.nextafter(10.0**e, 0), 1.2345678901234567 * 10.0**e) for e in range(-20, 25)]
    decades = [s * y for ys in near for y in ys for s in (1, -1)]
    powers = [2.0**e for e in range(-1074, 1024)]
    return [patterns, magnitudes, short, smoothed, np.array(edges + decades + powers), subnormals.view(np.float64)]


# The vector codes (enum mt_number_code) and what a processor needs to run each.
VECTOR_CODES = {
    "avx2": (lib.MT_NUMBER_CODE_AVX2, "AVX2 (x86-64-v3: AVX2, BMI1, BMI2, FMA, LZCNT, MOVBE, F16C)"),
    "avx512": (lib.MT_NUMBER_CODE_AVX512, "AVX-512 (x86-64-v4: AVX-512 F, BW, CD, DQ, VL)"),
}


def vector_code(name: str) -> int:
    """The C code of a vector code, or a skip that says why this processor cannot run it: a run
    that compared the portable code with itself would pass and prove nothing."""
    code, needs = VECTOR_CODES[name]
    if not lib.mt_number_code_runs(code):
        machine = platform.machine()
        if machine.lower() not in ("x86_64", "amd64"):
            pytest.skip(f"the {name} code is for x86-64 processors; this one is {machine}")
        pytest.skip(f"this processor has no {needs} (or this build no vector code, which takes GCC 12 or later)")
    return code


@pytest.mark.parametrize("code", list(VECTOR_CODES))
def test_vector_code_writes_what_the_portable_code_writes(rng, code):
    """Each vector code against its twin, the portable code, byte for byte: tables of one to 700
    columns (more than a group of slots holds), frames with their lines out of column order, every
    count of values left over from the lanes, every exponent width."""
    vector, portable = vector_code(code), lib.MT_NUMBER_CODE_PORTABLE
    for values in vector_cases(rng):
        for columns in (1, 3, 4, 5, 7, 8, 9, 62, 512, 513, 700):
            table = values[: len(values) // columns * columns].reshape(-1, columns)
            assert c_text("table", table, vector) == c_text("table", table, portable), columns
        for counts in ([1], [3, 3, 1], [6, 3, 3, 2, 1, 1, 3, 3, 3]):
            frames = values[: len(values) // sum(counts) * sum(counts)].reshape(-1, sum(counts))
            assert c_text("frames", frames, vector, counts=counts) == c_text("frames", frames, portable, counts=counts)
        for exponent_digits in (1, 3):
            table = values.reshape(-1, 1)
            assert c_text("table", table, vector, exponent_digits) == c_text("table", table, portable, exponent_digits)
    for n in range(20):  # fewer values than lanes, and what is left after them
        table = rng.standard_normal((n, 1)) * 10.0 ** rng.integers(-30, 30, (n, 1))
        assert c_text("table", table, vector) == c_text("table", table, portable)


def test_style_is_checked():
    for bad in (0, 18, -1):
        with pytest.raises(
            ValueError, match=rf"^digits must be in \[1, 17\] \(or None: the shortest exact text\), got {bad}$"
        ):
            format_number(1.0, digits=bad)
    with pytest.raises(TypeError, match=r"^digits must be an integer, got float 2.5$"):
        format_number(1.0, digits=2.5)
    for bad in (0, 4):
        with pytest.raises(ValueError, match=rf"^exponent_digits must be in \[1, 3\], got {bad}$"):
            format_number(1.0, exponent_digits=bad)
    with pytest.raises(ValueError, match=r"^newline must be one of b'\\n', b'\\r\\n', b'\\r'; got b'\\n\\r'$"):
        format_table(np.zeros((1, 1)), print, newline=b"\n\r")
    style = ffi.new("struct mt_format_style *", [18, 2, 0])
    buf, n = ffi.new("char[]", 64), ffi.new("size_t *")
    assert lib.mt_format_double(1.0, style, buf, n) == lib.MT_EINVAL
    assert lib.mt_format_table_bound(1, 1, style) == 2**64 - 1  # a bound no buffer meets


def test_the_codes_are_named_and_checked():
    """number_code() names the code that "best" stands for, the widest that number_codes() lists;
    a code that is not one, or that the processor does not run, is refused in Python and in C."""
    codes = number_codes()
    assert codes[0] == number_code() and codes[-1] == "portable"
    assert lib.mt_number_code() == {name: code for name, (code, _) in VECTOR_CODES.items()}.get(
        number_code(), lib.MT_NUMBER_CODE_PORTABLE
    )
    values = np.array([[1.5, -2.0, 1e-7, 0.1 + 0.2, 5e-324, 1e300, 123456.789, 0.0]])
    texts = set()
    for code in ("best", *codes):
        out: list[bytes] = []
        format_table(values, out.append, code=code)
        format_frames(values, 1, [b"k"], [0], [8], out.append, code=code)
        texts.add(b"".join(out))
    assert len(texts) == 1
    with pytest.raises(ValueError, match="code must be 'best' or one of"):
        format_table(values, print, code="sse2")
    for missing in {"avx512", "avx2"} - set(codes):
        with pytest.raises(ValueError, match=f"code '{missing}' does not run on this processor, which runs"):
            format_table(values, print, code=missing)
    buf, n = ffi.new("char[]", 64), ffi.new("size_t *")
    c_values = ffi.from_buffer("double[]", values)
    for bad in (-1, 4, *(VECTOR_CODES[name][0] for name in VECTOR_CODES if name not in codes)):
        assert not lib.mt_number_code_runs(bad)
        assert lib.mt_format_table(c_values, 1, 1, ffi.NULL, bad, buf, 64, n) == lib.MT_EINVAL


@pytest.mark.parametrize("newline", [b"\n", b"\r\n", b"\r"])
def test_newlines(newline):
    out: list[bytes] = []
    format_table(np.array([[1.5, -2.0], [3.0, 4.25]]), out.append, newline=newline)
    assert b"".join(out) == b"1.5 -2" + newline + b"3 4.25" + newline
    out.clear()
    format_frames(np.array([[1.5, -2.0], [3.0, 4.25]]), 7, [b"a", b"b"], [0, 1], [1, 1], out.append, newline=newline)
    assert b"".join(out) == newline.join([b"7", b"a 1.5", b"b -2", b"8", b"a 3", b"b 4.25", b""])


class Trickle(io.RawIOBase):
    """An unbuffered file that takes at most 1000 bytes a call, as a raw file may."""

    def __init__(self):
        self.data = bytearray()

    def writable(self):
        return True

    def write(self, b):
        taken = bytes(b[:1000])
        self.data += taken
        return len(taken)


@pytest.mark.parametrize("writer", ["table", "frames"])
def test_a_file_gets_the_text_a_function_gets(rng, tmp_path, writer):
    """Chunks go to a file straight from the writer's buffer, to a function as bytes it may keep
    (a list of them, joined after: the buffer is reused between chunks)."""
    values = rng.standard_normal((1000, 7)) * 100  # four chunks
    if writer == "table":
        write = functools.partial(format_table, values)
    else:
        write = functools.partial(format_frames, values, 1, [b"a", b"bb"], [0, 3], [3, 4])
    kept: list[bytes] = []
    write(kept.append)
    with open(tmp_path / "text", "wb") as f:
        write(f)
    trickle = Trickle()
    write(trickle)
    assert len(kept) == 4 and b"".join(kept) == (tmp_path / "text").read_bytes() == bytes(trickle.data)


# ---- the bounds of the buffers ------------------------------------------------------------


def test_the_longest_number_fits():
    worst = -2.2250738585072014e-308
    assert len(format_number(worst)) == len(format_number(worst, exponent_digits=3)) == lib.MT_NUMBER_MAX
    assert len(format_number(-1.2345678901234567e-100, digits=17, exponent_digits=3)) == lib.MT_NUMBER_MAX


@pytest.mark.parametrize("digits,exponent_digits,newline", [(0, 2, 0), (0, 3, 1), (17, 3, 1), (6, 1, 2)])
def test_bounds_hold_for_every_style(digits, exponent_digits, newline):
    """Frames and tables of the longest numbers, in a buffer of exactly the bound: they fit, and
    one byte less is refused before anything is written."""
    style = ffi.new("struct mt_format_style *", [digits, exponent_digits, newline])
    values = np.full((3, 5), -2.2250738585072014e-308)
    keys = [ffi.new("char[]", b"lhumerus"), ffi.new("char[]", b"x")]
    c_keys = ffi.new("const char *[]", keys)
    lens, offsets, counts = ffi.new("size_t[]", [8, 1]), ffi.new("size_t[]", [0, 3]), ffi.new("size_t[]", [3, 2])
    n = ffi.new("size_t *")
    c_values = ffi.from_buffer("double[]", values)
    first = FRAME_MAX - 2  # the longest frame numbers
    bound = lib.mt_format_bound(3, lens, counts, 2, style)
    buf = ffi.new("char[]", bound)
    best = lib.MT_NUMBER_CODE_BEST
    assert (
        lib.mt_format_frames(c_values, 3, 5, first, c_keys, lens, offsets, counts, 2, style, best, buf, bound, n) == 0
    )
    assert n[0] == bound if digits in (0, 17) else n[0] < bound  # the longest numbers meet it
    args = (c_values, 3, 5, first, c_keys, lens, offsets, counts, 2, style, best, buf, bound - 1, n)
    assert lib.mt_format_frames(*args) == lib.MT_ERANGE
    bound = lib.mt_format_table_bound(3, 5, style)
    buf = ffi.new("char[]", bound)
    assert lib.mt_format_table(c_values, 3, 5, style, best, buf, bound, n) == 0 and n[0] <= bound
    assert lib.mt_format_table(c_values, 3, 5, style, best, buf, bound - 1, n) == lib.MT_ERANGE
    empty_lines = lib.mt_format_table_bound(3, 0, style)  # no columns: the newlines still take room
    assert lib.mt_format_table(c_values, 3, 0, style, best, buf, empty_lines - 1, n) == lib.MT_ERANGE
    assert lib.mt_format_table(c_values, 3, 0, style, best, buf, empty_lines, n) == 0 and n[0] == empty_lines


def test_bounds_saturate():
    counts, lens = ffi.new("size_t[]", [2**62]), ffi.new("size_t[]", [1])
    assert lib.mt_format_bound(2**40, lens, counts, 1, ffi.NULL) == 2**64 - 1
    assert lib.mt_format_table_bound(2**40, 2**40, ffi.NULL) == 2**64 - 1


# ---- reading ------------------------------------------------------------------------------------


def check_reads_as_float(tokens: list[str]) -> None:
    """Each token reads as float() gives, through parse_number (text, and bytes: C's parser) and
    through the scanner."""
    want = [float(t) for t in tokens]
    assert_same_bits([parse_number(t) for t in tokens], want, tokens)
    assert_same_bits([parse_number(t.encode()) for t in tokens], want, tokens)
    assert_same_bits(read_back(tokens), want, tokens)


@st.composite
def decimals(draw, max_digits=800):
    digits = draw(st.text("0123456789", min_size=1, max_size=max_digits))
    if draw(st.booleans()):
        at = draw(st.integers(0, len(digits)))
        digits = digits[:at] + "." + digits[at:]
    if draw(st.booleans()):
        digits += draw(st.sampled_from("eE")) + draw(st.sampled_from(["", "+", "-"])) + str(draw(st.integers(0, 400)))
    return draw(st.sampled_from(["", "-", "+"])) + digits


@given(st.lists(decimals(), min_size=1, max_size=20))
@settings(max_examples=400, deadline=None)
def test_decimals_read_as_float(tokens):
    check_reads_as_float(tokens)


def test_random_decimals_of_any_length(rng):
    tokens = []
    for _ in range(20_000):
        n = int(
            rng.choice([1, 2, 8, 15, 16, 17, 18, 19, 20, 21, 40, 100, 300, 800])
            if rng.random() < 0.5
            else rng.integers(1, 801)
        )
        digits = "".join(map(str, rng.integers(0, 10, n)))
        at = int(rng.integers(0, n + 1))
        mantissa = digits[:at] + "." + digits[at:] if rng.random() < 0.7 else digits
        tokens.append(f"{rng.choice(['', '-', '+'])}{mantissa}e{int(rng.integers(-400, 401))}")
    check_reads_as_float(tokens)


def halfway_tokens(x: float) -> list[str]:
    """The exact midpoint between x and the next double up, and decimals just either side of it."""
    y = math.nextafter(x, math.inf)
    with localcontext() as context:
        context.prec = 2000
        mid = (Decimal(x) + (Decimal(y) if math.isfinite(y) else Decimal(2) ** 1024)) / 2
        unit = Decimal((0, (1,), mid.as_tuple().exponent))
        return [str(mid), str(mid + unit), str(mid - unit), str(mid) + "0" * 30 + "1", f"{mid:f}"[:780]]


def test_halfway_cases(rng):
    """Decimals exactly between two doubles read to the even one; a digit either side decides."""
    xs = [from_bits(int(b)) for b in rng.integers(1, 0x7FF0000000000000, 3000, dtype=np.uint64)]
    xs += [from_bits(b) for b in range(1, 50)] + [2.0**e for e in range(-1074, 1024, 7)]
    xs += [1.0, 9007199254740992.0, 1.7976931348623157e308, 2.2250738585072014e-308, 0.1]
    check_reads_as_float([t for x in xs for t in halfway_tokens(x)])


def test_extremes():
    with localcontext() as context:
        context.prec = 2000
        half_smallest = f"{Decimal(2.0**-1074) / 2:f}"  # 0.000...2470...5: 751 digits, exactly 2**-1075
    assert parse_number(half_smallest) == 0.0
    assert parse_number(half_smallest + "1") == 5e-324 == parse_number(half_smallest[:-1] + "6")
    overflow = str(2**1024 - 2**970)  # halfway between the largest double and 2**1024
    assert parse_number(overflow) == math.inf and parse_number(str(int(overflow) - 1)) == 1.7976931348623157e308
    check_reads_as_float(
        [
            half_smallest,
            overflow,
            "1" + "0" * 400,
            "0." + "0" * 400 + "1e400",
            "1e-99999999999999999999999",
            "-1e99999999999999999999",
            "0e99999999999999999999",
            "1." + "0" * 70,  # 72 characters: once refused
            "9007199254740993",
            "9007199254740993.000000000000000000001",
            "4.9406564584124654e-324",
            "2.4703282292062327e-324",
            "2.4703282292062328e-324",
            "1.7976931348623158e308",
            "8.98846567431158e307",
            "2.2250738585072011e-308",
            "0." + "0" * 5000 + "1e5000",
            "7" * 5000,
        ]
    )


GOOD = ["1", "-1", "+1", "1.", ".5", "-.5e-3", "+.5E+3", "1E5", "1e05", "007", "-0", "+0.0e-0", "00.00"]
GOOD += ["inf", "-inf", "+INF", "Infinity", "-iNfInItY", "nan", "NaN", "-nan", "+NAN"]
BAD = ["0x1p3", "0X10", "0x10", "nan(0x7)", "1_0", "1_000.5", "", ".", "-", "+", "e5", ".e5", "1e", "1e+", "1e-"]
BAD += ["+-1", "--1", "1..2", "1.2.3", "1e5.5", "1e5e5", "infinit", "infinityy", "in", "nana", "-nan(1)", "1,5"]
BAD += ["1.5f", "1d5", "1e1_0", "\u0661", "\u0661.5", "1\u00a0", "\u22121", "0b101", "1/2", "i", "n", "1+1"]


def test_the_grammar_accepts():
    for token in GOOD:
        got, want = parse_number(token), float(token)
        assert bits_of(got) == bits_of(want) or (math.isnan(got) and math.isnan(want)), token
        assert math.copysign(1, got) == math.copysign(1, want), token
    tokens = [t for t in GOOD if "nan" not in t.lower()]
    check_reads_as_float(tokens)


@pytest.mark.parametrize("token", BAD)
def test_the_grammar_refuses(token):
    with pytest.raises(NumberError, match="expected a number .*, found"):
        parse_number(token)
    with pytest.raises(NumberError, match="expected a number .*, found"):
        parse_number(token.encode())
    if not token:
        return  # no empty token in a line of text
    with pytest.raises(NumberError, match="expected a number as value 1"):
        scan_table(f"{token} 1\n".encode(), 1, 2)
    with pytest.raises(NumberError):
        scan_frames(f"1\nk 2 {token}\n".encode(), [b"k"], [0], [2], 2)


def test_blanks_around_a_token_are_refused():
    for token in (" 1", "1 ", "\t1", "1\n"):
        with pytest.raises(NumberError):
            parse_number(token)
    assert parse_number(b"2.5") == 2.5 == parse_number(bytearray(b"2.5"))


def test_scanning_on_all_cores(rng):
    """Long numbers over several pieces: every worker count gives float()'s values."""
    values = rng.standard_normal((40_000, 7)) / 3
    tokens = [repr(v) for v in values.ravel().tolist()]
    text = "\n".join(" ".join(tokens[i : i + 7]) for i in range(0, len(tokens), 7)).encode() + b"\n"
    assert len(text) > 2 << 20
    for workers in (1, 2, 3):
        assert scan_table(text, 40_000, 7, workers=workers).tobytes() == values.tobytes()


# ---- the locale -----------------------------------------------------------------------------

LOCALE_SCRIPT = r"""
import locale, sys
import numpy as np
from mtcore.text import format_frames, format_number, parse_number, scan_frames, scan_table
for name in ("de_DE.UTF-8", "de_DE.utf8", "fr_FR.UTF-8", "es_ES.UTF-8", "ru_RU.UTF-8", "nl_NL.UTF-8"):
    try:
        locale.setlocale(locale.LC_ALL, name)  # as a Qt or GTK application does with ""
    except locale.Error:
        continue
    if locale.localeconv()["decimal_point"] == ",":
        break
else:
    sys.exit(77)
values = np.array([[9.371713999999999, 1.5e-30, -17.3318, 2.0**-24, 1e22, 123456.5]])
out = []
format_frames(values, 1, [b"root"], [0], [6], out.append)
text = b"".join(out)
back, first = scan_frames(text, [b"root"], [0], [6], 6)
print(text.decode().split("\n")[1])
print(format_number(0.1, digits=3), format_number(1.23246e-13, exponent_digits=3))
long = "1" + "0" * 80 + ".5e-80"
print(parse_number("1.5e-30") == 1.5e-30, parse_number(long) == float(long))
print(back.tobytes() == values.tobytes(), scan_table(b"1.5e-30 0.1\n", 1, 2).tolist())
try:
    parse_number("1,5")
except ValueError:
    print("comma refused")
"""


def test_numbers_ignore_a_comma_locale():
    """A process whose C locale writes 1,5 (de_DE) writes and reads numbers with '.' all the same."""
    done = subprocess.run([sys.executable, "-c", LOCALE_SCRIPT], check=False, capture_output=True, text=True)
    if done.returncode == 77:
        pytest.skip(
            "no locale with a decimal comma is installed (apt-get install locales; enable de_DE.UTF-8 in "
            "/etc/locale.gen; locale-gen)"
        )
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == [
        "root 9.371713999999999 1.5e-30 -17.3318 5.960464477539063e-08 1e+22 123456.5",
        "0.1 1.23246e-013",
        "True True",
        "True [[1.5e-30, 0.1]]",
        "comma refused",
    ]


# ---- frame numbers ----------------------------------------------------------------------------


def test_frame_numbers_to_the_largest_round_trip():
    values = np.arange(6.0).reshape(3, 2)
    for first in (0, 1, FRAME_MAX - 2, 10**17 - 1):
        out: list[bytes] = []
        format_frames(values, first, [b"k"], [0], [2], out.append)
        back, got_first = scan_frames(b"".join(out), [b"k"], [0], [2], 2)
        assert got_first == first and back.tobytes() == values.tobytes()
    back, got_first = scan_frames(b"0000000000000000000000007\nk 1 2\n", [b"k"], [0], [2], 2)
    assert got_first == 7


def test_frame_numbers_past_the_range_are_refused():
    values = np.zeros((3, 1))
    for first in (-1, FRAME_MAX - 1, FRAME_MAX + 1, 2**63 - 1, 2**64):
        with pytest.raises(ValueError, match="cannot be written: frame text holds 0 .. 999999999999999999"):
            format_frames(values, first, [b"k"], [0], [1], print)
    key = ffi.new("char[]", b"k")
    keys, lens, offsets, counts = ffi.new("const char *[]", [key]), *(ffi.new("size_t[]", [v]) for v in (1, 0, 1))
    buf, n = ffi.new("char[]", 1000), ffi.new("size_t *")
    for first in (-1, 2**63 - 1, FRAME_MAX - 1):  # the C side checks again, without undefined behaviour
        status = lib.mt_format_frames(
            ffi.from_buffer("double[]", values), 3, 1, first, keys, lens, offsets, counts, 1, ffi.NULL,
            lib.MT_NUMBER_CODE_BEST, buf, 1000, n,
        )  # fmt: skip
        assert status == lib.MT_EFRAMERANGE
    for text, line in ((b"1000000000000000000\nk 1\n", 1), (b"999999999999999999\nk 1\n1000000000000000000\nk 2\n", 3)):
        with pytest.raises(SequenceError, match=r"frame number '1000000000000000000' is past the largest") as caught:
            scan_frames(text, [b"k"], [0], [1], 1)
        assert caught.value.line == line
    with pytest.raises(SequenceError, match="past the largest"):
        scan_frames(b"99999999999999999999999999999999999999\nk 1\n", [b"k"], [0], [1], 1)


# ---- the style of a file --------------------------------------------------------------------


def test_text_style():
    assert text_style(b"") == (b"\n", 2, b"\n")
    assert text_style(b"1\nroot 1 2\n") == (b"\n", 2, b"\n")
    assert text_style(b"1\r\nroot 1 2.5e-05\r\n") == (b"\r\n", 2, b"\r\n")
    assert text_style(b"1\rroot 1e-5\r") == (b"\r", 1, b"\r")
    assert text_style(b"1\nroot 1.23246e-013 5e-14\r\nx 1\r\n") == (b"\r\n", 3, b"\n")
    assert text_style(b"joint_e-01 1e-14\n") == (b"\n", 2, b"\n")  # a name is no exponent
    assert text_style(b"e-012 3.5E+007\n") == (b"\n", 3, b"\n")
    assert text_style(b"x 1e-0005\n") == (b"\n", 3, b"\n")  # more than 3 cannot be written: 3


@pytest.mark.parametrize("path", ["cmu/01_01.amc", "hdm05/HDM_bd_hopBothLegs1hops_005_120.amc"])
def test_files_written_back_byte_for_byte(data_dir, path):
    """CMU and HDM05 write %.6g with three exponent digits: read, then written with the style
    text_style finds and digits=6, the frames come back byte for byte (HDM05 ends its frame
    number lines in LF and the others in CRLF; one newline is written for all)."""
    data = (data_dir / path).read_bytes()
    body = data[re.search(rb"(?m)^1\s*$", data).start() :]
    lines = re.split(rb"\r?\n", body)
    first_frame = [line for line in lines[1 : next(i for i in range(1, len(lines)) if lines[i].isdigit())]]
    keys = [line.split()[0] for line in first_frame]
    counts = [len(line.split()) - 1 for line in first_frame]
    offsets = np.cumsum([0, *counts[:-1]]).tolist()
    values, first = scan_frames(body, keys, offsets, counts, sum(counts))
    newline, exponent_digits, _ = text_style(data)
    assert (newline, exponent_digits) == (b"\r\n", 3)
    out: list[bytes] = []
    format_frames(values, first, keys, offsets, counts, out.append, digits=6, exponent_digits=3, newline=newline)
    assert b"".join(out).replace(b"\r\n", b"\n") == body.replace(b"\r\n", b"\n")
    if path.startswith("cmu"):
        assert b"".join(out) == body


def test_the_table_generator_is_committed():
    """csrc/number_pow10.h is what csrc/gen_pow10.py writes (which also checks the fixed-point logarithms)."""
    csrc = SOURCE / "csrc"
    if not (csrc / "gen_pow10.py").is_file():
        pytest.skip(NO_SOURCE)
    done = subprocess.run([sys.executable, str(csrc / "gen_pow10.py")], capture_output=True, text=True, check=True)
    assert done.stdout == (csrc / "number_pow10.h").read_text()


# ---- the readers of header numbers use the same grammar --------------------------------------


@pytest.mark.parametrize(
    "change",
    [
        (b"OFFSET 0.00 0.00 0.00", b"OFFSET 1_0 0.00 0.00"),
        (b"OFFSET 0.00 0.00 0.00", b"OFFSET 0x10 0.00 0.00"),
        (b"Frame Time: 0.033333", b"Frame Time: 0x1p-5"),
        (b"Frame Time: 0.033333", b"Frame Time: 3_3e-3"),
        (b"Frames: 2", b"Frames: 0_2"),
    ],
)
def test_bvh_header_numbers_follow_the_grammar(change):
    bvh = (
        b"HIERARCHY\nROOT hip\n{\n\tOFFSET 0.00 0.00 0.00\n\tCHANNELS 3 Xposition Yposition Zposition\n"
        b"\tEnd Site\n\t{\n\t\tOFFSET 0 1 0\n\t}\n}\nMOTION\nFrames: 2\nFrame Time: 0.033333\n1 2 3\n4 5 6\n"
    )
    assert mt.read_bvh(io.BytesIO(bvh)).frames == 2
    with pytest.raises(mt.FormatError, match="expected"):
        mt.read_bvh(io.BytesIO(bvh.replace(*change)))


@pytest.mark.parametrize("token", ["1_0", "0x1p3", "nan(1)", "\u0661"])
def test_asf_numbers_follow_the_grammar(data_dir, token):
    asf = (data_dir / "cmu" / "01.asf").read_bytes()
    line = re.compile(rb"(?m)^\s*length (\S+)").search(asf, asf.index(b":bonedata"))
    bad = asf[: line.start(1)] + token.encode() + asf[line.end(1) :]
    with pytest.raises(mt.NumberError, match=re.escape(f"expected a number for length, found '{token}'")) as caught:
        mt.read_asf(io.BytesIO(bad))
    assert caught.value.line == asf[: line.start(1)].count(b"\n") + 1
