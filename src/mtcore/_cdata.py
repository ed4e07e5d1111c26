"""numpy arrays as C pointers for the kernels."""

from __future__ import annotations

import numpy as np

from ._mtcore import ffi


def c_array(a: np.ndarray | None, kind: str = "double[]"):
    """A pointer to a C-contiguous array's data, NULL for None (an empty array is a valid pointer)."""
    # numpy arrays export the buffer protocol; the cffi stubs do not know ndarray as a Buffer
    return ffi.NULL if a is None else ffi.from_buffer(kind, a)  # type: ignore[call-overload]
