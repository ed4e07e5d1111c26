"""Coverage-guided fuzzing of the four scanners of text, with atheris (libFuzzer for Python).

    python fuzz/fuzz_scanners.py TARGET [libFuzzer options] [CORPUS_DIR ...]

TARGET is one of TARGETS: ``scan_frames`` (AMC frame text, mt_scan_frames), ``scan_table``
(a BVH MOTION table, mt_scan_table), ``read_asf`` and ``read_bvh`` (the readers of
motiontheater).  Without a corpus directory, build/fuzz/TARGET is used, seeded with small
texts written here and, where the real capture corpus is found (tests/conftest.py's DATA),
with its files.  Every input must give a parsed result or a ValueError (FormatError is one):
anything else (another exception, a crash, a sanitizer report, a hang) is a finding, which
libFuzzer saves in build/fuzz/findings/TARGET-crash-* (or -timeout-*).  fuzz/README.md says more.
"""

from __future__ import annotations

import io
import os
import sys
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DATA = Path(os.environ.get("MOTIONTHEATER_DATA", ROOT.parent / "shared" / "data"))

KEYS = [b"root", b"lfemur", b"ltibia", b"head"]
OFFSETS, COUNTS, CHANNELS = [0, 6, 9, 0], [6, 3, 1, 0], 11


def _import_targets() -> None:
    """The modules under test (instrumented for coverage when called inside atheris.instrument_imports)."""
    global mt, text
    import motiontheater as mt
    from mtcore import text


def scan_frames(data: bytes) -> None:
    """Frame text after one byte that chooses the split: one piece, or pieces of 32 bytes
    and more (each scanned on its own thread, then joined: the borders are where bugs hide)."""
    if not data:
        return
    text._PIECE_BYTES = 32 if data[0] & 1 else 1 << 20
    try:
        values, first = text.scan_frames(data[1:], KEYS, OFFSETS, COUNTS, CHANNELS, workers=4)
    except ValueError:
        return
    assert values.shape[1] == CHANNELS and isinstance(first, int)


def scan_table(data: bytes) -> None:
    """A table of data[0] % 8 rows and data[1] % 8 columns, split in pieces or not as above."""
    if len(data) < 3:
        return
    rows, columns = data[0] % 8, data[1] % 8
    text._PIECE_BYTES = 16 if data[2] & 1 else 1 << 20
    try:
        values = text.scan_table(data[3:], rows, columns, workers=4)
    except ValueError:
        return
    assert values.shape == (rows, columns)


def read_asf(data: bytes) -> None:
    try:
        mt.read_asf(io.BytesIO(data))
    except ValueError:
        return


def read_bvh(data: bytes) -> None:
    """Read, then forward kinematics over what was read (the tables the reader built)."""
    try:
        motion = mt.read_bvh(io.BytesIO(data))
    except ValueError:
        return
    positions = motion.positions()
    assert positions.shape[0] == motion.frames


TARGETS: dict[str, Callable[[bytes], None]] = {
    "scan_frames": scan_frames,
    "scan_table": scan_table,
    "read_asf": read_asf,
    "read_bvh": read_bvh,
}

ASF = b"""# a small skeleton
:version 1.10
:name tiny
:units
  mass 1.0
  length 0.45
  angle deg
:documentation
  written for the fuzzer
:root
  order TX TY TZ RX RY RZ
  axis XYZ
  position 0 0 0
  orientation 0 0 0
:bonedata
  begin
    id 1
    name lfemur
    direction 0.34 -0.93 0
    length 7.1
    axis 0 0 20 XYZ
    dof rx ry rz
    limits (-160.0 20.0)
           (-70.0 70.0)
           (-60.0 70.0)
  end
  begin
    id 2
    name ltibia
    direction 0.34 -0.93 0
    length 7.5
    axis 0 0 20 XYZ
    dof rx
    limits (-10.0 170.0)
  end
:hierarchy
  begin
    root lfemur
    lfemur ltibia
  end
"""

BVH = b"""HIERARCHY
ROOT Hips
{
\tOFFSET 0.0 0.0 0.0
\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
\tJOINT Chest
\t{
\t\tOFFSET 0.0 5.2 0.0
\t\tCHANNELS 3 Zrotation Xrotation Yrotation
\t\tEnd Site
\t\t{
\t\t\tOFFSET 0.0 4.0 0.0
\t\t}
\t}
}
MOTION
Frames: 2
Frame Time: 0.0083333
1.5 90.2 -3 0.5 -10 2 1e-3 4 -5
1.25 90.1 -3.5 1 -9.5 2.25 0 4.5 -5.5
"""


def seeds(target: str) -> list[bytes]:
    """Small valid inputs, and the real files of the corpus where it is found."""
    frames = b"1\nroot 0 0 0 0 0 0\nlfemur 1 2 3\nltibia 4\nhead\n2\r\nltibia -5e-3\r\nroot 9.37 17.8 -1 .5 6 7\r\nlfemur 1 2 3\r\n"
    own = {
        "scan_frames": [b"\x00" + frames, b"\x01" + frames],
        "scan_table": [b"\x02\x03\x00" + b"1 2 3\n4 5 6\n", b"\x02\x03\x01" + b"1 -2e5 3\r\n4\t5 nan\r\n"],
        "read_asf": [ASF],
        "read_bvh": [BVH],
    }[target]
    real = {"scan_frames": "*/*.amc", "read_asf": "*/*.asf", "read_bvh": "bvh/*.bvh"}.get(target)
    if real and DATA.is_dir():
        for path in sorted(DATA.glob(real))[:12]:
            body = path.read_bytes()[:65536]
            if target == "scan_frames":  # the frames, without the AMC header
                start = body.find(b"\n1\n")
                body = b"\x00" + body[start + 1 :] if start >= 0 else b""
            if body:
                own.append(body)
    return own


def _gcc_coverage(target: Callable[[bytes], None]) -> Callable[[bytes], None]:
    """With MT_FUZZ_GCC_COVERAGE naming fuzz/gcc_coverage.c built as a shared library (the fuzzing
    build of .ci/sanitize links the C module, compiled with -fsanitize-coverage=trace-pc, to it):
    the shim's counters are registered with libFuzzer at the first input, once atheris loaded it."""
    import ctypes

    shim_path = os.environ.get("MT_FUZZ_GCC_COVERAGE")
    if not shim_path:
        return target
    shim = ctypes.CDLL(shim_path)
    shim.mt_fuzz_connect.argtypes = [ctypes.c_void_p] * 2
    connected = False

    def connect_then(data: bytes) -> None:
        nonlocal connected
        if not connected:
            maps = Path("/proc/self/maps").read_text()
            core = next(line.split()[-1] for line in maps.splitlines() if "core_with_libfuzzer" in line)
            fuzzer = ctypes.CDLL(core)
            hooks = (fuzzer[f"__sanitizer_cov_{n}"] for n in ("8bit_counters_init", "pcs_init"))
            shim.mt_fuzz_connect(*(ctypes.cast(hook, ctypes.c_void_p) for hook in hooks))
            connected = True
        target(data)

    return connect_then


def main(argv: list[str]) -> None:
    import atheris

    if len(argv) < 2 or argv[1] not in TARGETS:
        sys.exit(f"usage: {argv[0]} {{{','.join(TARGETS)}}} [libFuzzer options] [CORPUS_DIR ...]")
    target = argv[1]
    options = [a for a in argv[2:] if a.startswith("-")]
    corpora = [a for a in argv[2:] if not a.startswith("-")]
    if not corpora:
        corpus = ROOT / "build" / "fuzz" / target
        corpus.mkdir(parents=True, exist_ok=True)
        for i, seed in enumerate(seeds(target)):
            (corpus / f"seed-{i}").write_bytes(seed)
        corpora = [str(corpus)]
    dictionary = Path(__file__).with_name(f"{target.split('_')[-1]}.dict")
    if not any(o.startswith("-dict=") for o in options):
        options.append(f"-dict={dictionary}")
    if not any(o.startswith("-artifact_prefix=") for o in options):
        findings = ROOT / "build" / "fuzz" / "findings"
        findings.mkdir(parents=True, exist_ok=True)
        options.append(f"-artifact_prefix={findings}/{target}-")
    run = _gcc_coverage(TARGETS[target])
    with atheris.instrument_imports(include=["motiontheater", "mtcore"]):
        _import_targets()
    atheris.Setup([argv[0], *options, *corpora], run)
    atheris.Fuzz()


if __name__ == "__main__":
    main(sys.argv)
else:
    _import_targets()
