"""Frame rates from frame times printed with few digits.

A BVH file states its rate as a Frame Time in seconds, and most producers print it rounded:
``0.0333333`` is 30.00003 Hz taken literally, ``0.008`` could be 120 or 125 Hz.  The rate a
printed time stands for is the one it rounds from: a rate r whose 1/r lies within half a unit
of the last printed digit, the common capture and video rates first, then whole rates, the
nearest to the literal rate among those; a time printed in full (``0.03333333333333333``) is
its own rate.  The text itself is kept and written back as found.
"""

from __future__ import annotations

import re

from mtcore.text import parse_number

# capture and video rates, as a producer would have chosen them
COMMON = (24.0, 25.0, 30.0, 48.0, 50.0, 60.0, 72.0, 90.0, 96.0, 100.0, 120.0, 125.0, 144.0, 150.0, 180.0,
          200.0, 240.0, 250.0, 300.0, 360.0, 400.0, 480.0, 500.0, 960.0, 1000.0,
          24000 / 1001, 30000 / 1001, 60000 / 1001)  # fmt: skip
_DECIMAL = re.compile(r"^[+]?(\d*)(?:\.(\d*))?(?:[eE]([+-]?\d+))?$")


def rate_of_frame_time(text: str) -> float:
    """The frame rate (Hz) that a frame time printed as ``text`` (seconds) stands for.

    ValueError for text that is not a positive finite number."""
    seconds = parse_number(text.strip())
    if not 0 < seconds < float("inf"):
        raise ValueError(f"a frame time must be a positive number of seconds, got {text.strip()!r}")
    literal = 1.0 / seconds
    half = _half_unit(text.strip())
    if half is None:
        return literal
    for candidates in (COMMON, (float(round(literal)),)):
        fitting = [r for r in candidates if r > 0 and abs(1.0 / r - seconds) <= half]
        if fitting:
            return min(fitting, key=lambda r: abs(r - literal))
    return literal


def _half_unit(text: str) -> float | None:
    """Half a unit of the last digit of a decimal's text: how far the value it was rounded from may
    lie (None for text with 16 or more significant digits, which is the double itself)."""
    match = _DECIMAL.match(text)
    if match is None:
        return None
    whole, fraction, exponent = match.group(1), match.group(2) or "", int(match.group(3) or 0)
    digits = (whole + fraction).lstrip("0")
    if len(digits) >= 16:
        return None
    return 0.5 * 10.0 ** (exponent - len(fraction))
