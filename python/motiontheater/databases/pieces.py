"""A take checked a piece at a time, so that what the check holds does not grow with the take.

A take longer than PIECE_FRAMES is cut into pieces of that many frames, each checked with
MARGIN_SECONDS of its neighbours on either side (the frames around a finding that the
detectors read: the feet's lowest two seconds around, a turn-over's half second, a hold's
context).  A piece keeps the findings that begin in its own frames, and those that go on into
them from before; a finding that runs on past the frames it was checked with is joined to its
continuation in the next piece (a long hold, a gap, the take's jitter or its floor: a finding
over the whole take is in every piece).  The frames come as blocks of any size (a take read whole, or an AMC
read a piece of text at a time), so that a take need not be in memory at all.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterable

import numpy as np

from ..model.motion import Motion
from .findings import Finding

PIECE_FRAMES = 8192
"""Frames checked at once (68 s at 120 Hz: 4 MB of values for 62 channels, about 30 MB with
every joint's place and turn)."""
MARGIN_SECONDS = 3.0
"""Seconds of the neighbouring frames read on either side of a piece."""

Check = Callable[[Motion, bool, bool], list[Finding]]
"""What checks a piece: (the piece, whether it begins the take, whether it ends it) -> findings."""


def check_frames(template: Motion, blocks: Iterable[np.ndarray], check: Check) -> list[Finding]:
    """The findings of the take whose frames are ``blocks`` (rows of the take, in order) and
    whose skeleton, rate and first frame are ``template``'s, checked a piece at a time."""
    margin = max(64, round(MARGIN_SECONDS * template.frame_rate))
    pieces: list[list[Finding]] = []
    held, start = np.zeros((0, len(template.skeleton.channels))), 0  # rows start .. of the take, in hand
    core, ended = 0, False  # the first row of the next piece's own frames
    source = iter(blocks)
    while True:
        while not ended and start + len(held) < core + PIECE_FRAMES + 2 * margin:
            block = next(source, None)
            if block is None:
                ended = True
            else:
                held = block if not len(held) else np.concatenate([held, block])
        known = start + len(held)
        last_piece = ended and known - core <= PIECE_FRAMES + margin  # no short piece after it
        end = known if last_piece else core + PIECE_FRAMES
        a, b = max(core - margin, 0), min(end + margin, known)
        piece = template.replace(values=held[a - start : b - start], first_frame=template.first_frame + a)
        found = check(piece, a == 0, last_piece)
        first, stop = template.first_frame + core, template.first_frame + end
        # the findings that begin in its own frames, and those that go on into them from the piece
        # before (joined to it there, or, where it told none, begun where this piece sees them begin)
        pieces.append([f for f in found if first <= f.first < stop or (f.first < first <= f.last)])
        if last_piece:
            break
        core = end
        drop = max(core - margin - start, 0)  # pieces shorter than the margin keep every row still in reach
        held, start = held[drop:], start + drop
    return _joined(pieces, template.frame_rate)


def _joined(pieces: list[list[Finding]], rate: float) -> list[Finding]:
    """The pieces' findings, each that goes on in the next piece joined to its continuation."""
    if len(pieces) == 1:  # nearly every take: nothing to join
        return pieces[0]
    out: list[Finding] = []
    open_: dict[tuple[str, tuple[str, ...]], int] = {}  # (kind, joints) -> index in out of the last piece's
    for found in pieces:
        reached: dict[tuple[str, tuple[str, ...]], int] = {}
        for f in found:
            key = (f.kind, f.joints)
            i = open_.get(key)
            if i is not None and f.first <= out[i].last + 1 and f.last > out[i].last:
                out[i] = _extended(out[i], f, rate)
            elif i is None or f.first > out[i].last + 1:
                out.append(f)
                i = len(out) - 1
            reached[key] = i
        open_ = reached
    return out


def _extended(f: Finding, more: Finding, rate: float) -> Finding:
    """A finding run on to where its continuation ends: the worse severity, the larger size (a
    duration grown by the frames added), the fix only where both parts had the same."""
    longer = f.size + (more.last - f.last) / rate if f.unit == "s" else max(f.size, more.size)
    return dataclasses.replace(
        f,
        last=more.last,
        severity=max(f, more, key=lambda x: x.rank).severity,
        size=round(longer, 6),
        detail=f"{f.detail} (on to frame {more.last})",
        fix=f.fix if f.fix == more.fix else (),
    )
