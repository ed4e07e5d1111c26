"""Mutated real files: every reader either reads them or raises a FormatError naming the line, never
anything else (no crash, no hang, no stray exception type)."""

import io
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import motiontheater as mt
from conftest import DATA

pytestmark = pytest.mark.skipif(not DATA.is_dir(), reason=f"real capture corpus not found at {DATA}")


def sample(path: Path) -> bytes:
    return path.read_bytes() if DATA.is_dir() else b""


AMC = sample(DATA / "cmu" / "02_03.amc").split(b"\n21\n")[0] + b"\n"  # 20 whole frames
ASF = sample(DATA / "cmu" / "02.asf")
BVH = sample(DATA / "bvh" / "walk01.bvh")
NOISE = st.sampled_from(
    [
        b"",
        b" ",
        b"\t",
        b"\n",
        b"\r",
        b"x",
        b"-",
        b".",
        b"e",
        b"1e999",
        b"nan",
        b"{",
        b"}",
        b"#",
        b":",
        b"root",
        b"\xff",
        b"999999999999999999999",
        b"0" * 40,
    ]
)


@st.composite
def mutated(draw, text: bytes):
    data = bytearray(text)
    for _ in range(draw(st.integers(1, 4))):
        at = draw(st.integers(0, len(data)))
        cut = draw(st.integers(0, 8))
        data[at : at + cut] = draw(NOISE)
    return bytes(data)


def survives(read) -> None:
    try:
        read()
    except mt.FormatError:
        pass


SETTINGS = dict(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@given(mutated(AMC))
@settings(**SETTINGS)
def test_mutated_amc(data):
    skeleton = mt.read_asf(io.BytesIO(ASF))
    survives(lambda: mt.read_amc(io.BytesIO(data), skeleton).positions())


def test_the_unmutated_samples_read():
    assert mt.read_amc(io.BytesIO(AMC), mt.read_asf(io.BytesIO(ASF))).frames == 20
    assert mt.read_bvh(io.BytesIO(BVH)).frames == 101


@given(mutated(ASF))
@settings(**SETTINGS)
def test_mutated_asf(data):
    survives(lambda: mt.read_asf(io.BytesIO(data)))


@given(mutated(BVH))
@settings(**SETTINGS)
def test_mutated_bvh(data):
    survives(lambda: mt.read_bvh(io.BytesIO(data)).positions())


@given(st.binary(max_size=300), st.integers(0, 4), st.integers(0, 5))
@settings(max_examples=1000, deadline=None)
def test_c_scanners_take_any_bytes(data, rows, columns):
    from mtcore.errors import FormatError
    from mtcore.text import scan_frames, scan_table

    for scan in (lambda: scan_frames(data, [b"a", b"bb"], [0, 1], [1, 2], 3), lambda: scan_table(data, rows, columns)):
        try:
            scan()
        except FormatError:
            pass
