"""mtcore: the array-level core of motiontheater.

Fast one-dimensional smoothing filters in C, drop-in replacements for their
scipy.ndimage counterparts (same signatures, defaults and results)::

    from mtcore import median_filter1d, uniform_filter1d, binomial_filter1d

and frame text (AMC bodies) scanned into arrays and written back exactly
(:func:`scan_frames`, :func:`format_frames`); rotations of whole arrays (Euler
angles, matrices, quaternions, rotation vectors) in :mod:`mtcore.rotations`;
signal processing (a band equaliser, zero-phase Butterworth filtering,
polyphase resampling, gap filling; scipy.signal's signatures) in
:mod:`mtcore.signal`; search by example (dynamic time warping with LB_Keogh pruning,
exact k nearest neighbours, relational features and their inverted index) in
:mod:`mtcore.search`.
"""

from . import errors, search, signal
from ._parallel import cpu_count, share_cores
from .filters import MODES, binomial_filter1d, filter_block, median_filter1d, pascal_weights, uniform_filter1d
from .text import format_frames, format_number, scan_frames

__all__ = [
    "MODES",
    "binomial_filter1d",
    "cpu_count",
    "errors",
    "filter_block",
    "format_frames",
    "format_number",
    "median_filter1d",
    "pascal_weights",
    "scan_frames",
    "search",
    "share_cores",
    "signal",
    "uniform_filter1d",
]
