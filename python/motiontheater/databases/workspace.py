"""Memory the check reuses from one take to the next.

A database is checked a take after another, and each take's forward kinematics fills arrays as
large as its values.  Memory fresh from the system costs a page fault a page, more than the
kinematics of a short take; arrays kept from the take before cost nothing.  A workspace is lent
to one check at a time (:func:`lent`), per thread, and keeps at most KEPT_BYTES: a longer take's
arrays are new and freed with it.
"""

from __future__ import annotations

import contextlib
import math
import threading
from collections.abc import Iterator

import numpy as np

KEPT_BYTES = 16 << 20
"""The most a workspace keeps between takes (a take of 40 joints and 8,000 frames fits)."""


class Workspace:
    """Float64 arrays by name, each cut from a buffer kept for the next take."""

    def __init__(self) -> None:
        self._buffers: dict[str, np.ndarray] = {}

    def array(self, name: str, shape: tuple[int, ...]) -> np.ndarray:
        """An uninitialised C-contiguous float64 array of ``shape``, kept as ``name`` if it fits."""
        size = math.prod(shape)
        buffer = self._buffers.get(name)
        if buffer is None or len(buffer) < size:
            buffer = np.empty(size)
            kept = sum(len(b) for key, b in self._buffers.items() if key != name)
            if (kept + size) * buffer.itemsize <= KEPT_BYTES:
                self._buffers[name] = buffer
        return buffer[:size].reshape(shape)


_idle = threading.local()


@contextlib.contextmanager
def lent() -> Iterator[Workspace]:
    """A workspace of this thread's that no other check holds, for the duration."""
    pool: list[Workspace] = _idle.__dict__.setdefault("pool", [])
    space = pool.pop() if pool else Workspace()
    try:
        yield space
    finally:
        pool.append(space)
