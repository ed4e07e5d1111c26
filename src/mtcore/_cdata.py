"""numpy arrays as C pointers for the kernels."""

from __future__ import annotations

import numpy as np

from ._mtcore import ffi


def c_array(a: np.ndarray | None, kind: str = "double[]"):
    """A pointer to a C-contiguous array's data, NULL for None (an empty array is a valid pointer)."""
    return ffi.NULL if a is None else ffi.from_buffer(kind, a)
