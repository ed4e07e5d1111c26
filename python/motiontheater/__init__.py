"""motiontheater: motion-capture data (ASF/AMC, BVH) read, cut, splice and smoothed.

The numeric work is done by :mod:`mtcore`, the package's C core; its
smoothing filters are re-exported here.
"""

from importlib.metadata import PackageNotFoundError, version

from mtcore import binomial_filter1d, median_filter1d, pascal_weights, uniform_filter1d

try:
    __version__ = version("motiontheater")
except PackageNotFoundError:  # running from a source tree that was never installed
    __version__ = "0+unknown"

__all__ = [
    "__version__",
    "binomial_filter1d",
    "median_filter1d",
    "pascal_weights",
    "uniform_filter1d",
]
