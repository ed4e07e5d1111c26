"""Where a take's file breaks off or goes on past what its header says: what a reader that keeps
the frames a file holds whole (``read_take_frames``) found, for the check to tell."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Cut:
    """How a take's file disagrees with itself: ``reason`` (a sentence), the ``line`` where, the
    whole frames read (``held``) and those its header declares (``declared``, None where the
    format declares none, as AMC)."""

    reason: str
    line: int | None
    held: int
    declared: int | None = None
