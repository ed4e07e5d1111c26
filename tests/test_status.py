"""The one status map (src/mtcore/_status.py): every C status code has its exception and its message."""

import re

import pytest

from conftest import SOURCE, needs_source
from mtcore import errors
from mtcore._mtcore import ffi, lib
from mtcore._status import _EXCEPTIONS, check

HEADER = SOURCE / "csrc" / "mtcore.h"


def status_codes() -> dict[str, int]:
    """The MT_E* names of enum mt_status in the header, with their values as cffi has them."""
    body = re.search(r"enum mt_status\s*{(.*?)};", HEADER.read_text(), re.DOTALL).group(1)
    return {name: getattr(lib, name) for name in re.findall(r"\b(MT_E\w+)\s*=", body)}


@needs_source
def test_every_status_code_is_mapped():
    codes = status_codes()
    assert "MT_ERANGE" in codes and len(codes) >= 10
    assert not {name for name, code in codes.items() if code not in _EXCEPTIONS}
    assert set(_EXCEPTIONS) == set(codes.values())


@needs_source
def test_every_status_code_has_its_own_message():
    messages = {name: ffi.string(lib.mt_strerror(code)).decode() for name, code in status_codes().items()}
    unknown = ffi.string(lib.mt_strerror(12345)).decode()
    assert unknown not in messages.values()
    assert len(set(messages.values())) == len(messages)


# every mapped code, which the test above finds to be every code of the header
@pytest.mark.parametrize("code", sorted(_EXCEPTIONS))
def test_check_raises_the_mapped_exception_naming_the_call(code):
    with pytest.raises(_EXCEPTIONS[code], match=rf"^mt_something: .+ \(status {code}\)$"):
        check(code, "mt_something")


def test_format_errors_take_their_reason_and_line_from_the_caller():
    def describe(status):
        return "more rows than the header says", 12, False

    with pytest.raises(errors.SequenceError) as caught:
        check(lib.MT_ERANGE, "mt_scan_table", describe)
    assert (caught.value.reason, caught.value.line) == ("more rows than the header says", 12)
    with pytest.raises(errors.TruncatedError):
        check(lib.MT_EMISSING, "mt_scan_table", lambda status: ("cut short", 3, True))


def test_success_raises_nothing():
    check(lib.MT_OK, "mt_anything")
