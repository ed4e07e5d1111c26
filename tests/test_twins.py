"""Every C entry point against its slow twin (tests/twins), from one list, in the manner of
bottleneck's func_dict: none missing, none stale, results equal, inputs untouched."""

import copy
import math
import re

import numpy as np
import pytest

from conftest import SOURCE, needs_source
from twins import EXEMPT, TWINS, Twin

HEADER = SOURCE / "csrc" / "mtcore.h"


def entry_points(header: str) -> set[str]:
    """The mt_* functions declared between the MT_CDEF markers (what cffi exposes)."""
    region = header[header.index("/* MT_CDEF_BEGIN */") : header.index("/* MT_CDEF_END */")]
    return set(re.findall(r"\b(mt_\w+)\s*\(", re.sub(r"/\*.*?\*/", "", region, flags=re.DOTALL)))


def test_the_header_parser_finds_declarations():
    text = "/* MT_CDEF_BEGIN */\nint mt_a(int x);\n/* mt_b(1) in a comment */\nsize_t\nmt_c (void);\n/* MT_CDEF_END */"
    assert entry_points(text) == {"mt_a", "mt_c"}


@needs_source
def test_every_entry_point_has_a_twin():
    declared = entry_points(HEADER.read_text())
    missing = declared - TWINS.keys() - EXEMPT.keys()
    assert not missing, f"C entry points without a slow twin in tests/twins (or a reason in EXEMPT): {sorted(missing)}"


@needs_source
def test_no_twin_for_an_entry_point_that_is_gone():
    declared = entry_points(HEADER.read_text())
    assert not (TWINS.keys() | EXEMPT.keys()) - declared
    assert not TWINS.keys() & EXEMPT.keys()


@pytest.mark.parametrize("name", sorted(TWINS))
def test_kernel_equals_its_twin(name):
    twin = TWINS[name]
    cases = twin.cases(np.random.default_rng(20041122))
    assert cases
    for case in cases:
        twin.same(twin.fast(*case), twin.slow(*case))


def test_a_wrong_twin_is_caught():
    """The comparison can fail: a twin off by one ulp in one value, or of the wrong shape."""
    for name in ("mt_filter1d", "mt_combine", "mt_slerp"):
        twin = TWINS[name]
        case = next(c for c in twin.cases(np.random.default_rng(1)) if np.asarray(twin.slow(*c)).size)
        want = np.asarray(twin.slow(*case), dtype=float)
        bent = want.copy()
        finite = np.flatnonzero(np.isfinite(bent) & (bent != 0))
        bent.flat[finite[0]] *= 1 + 1e-6
        with pytest.raises(AssertionError):
            twin.same(twin.fast(*case), bent)
        with pytest.raises(AssertionError):
            twin.same(twin.fast(*case), want[..., :0])


def snapshot(value):
    return copy.deepcopy(value)


def assert_unchanged(before, after) -> None:
    if isinstance(before, np.ndarray):
        assert before.tobytes() == after.tobytes() and before.shape == after.shape
    elif isinstance(before, (tuple, list)):
        for b, a in zip(before, after, strict=True):
            assert_unchanged(b, a)
    elif isinstance(before, float):
        assert before == after or (math.isnan(before) and math.isnan(after))
    elif not hasattr(before, "__dict__"):
        assert before == after


@pytest.mark.parametrize("name", sorted(TWINS))
def test_inputs_are_never_modified(name):
    twin: Twin = TWINS[name]
    for case in twin.cases(np.random.default_rng(7)):
        before = snapshot(case)
        twin.fast(*case)
        assert_unchanged(before, case)
