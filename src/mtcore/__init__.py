"""mtcore: the array-level core of motiontheater.

Fast one-dimensional smoothing filters in C, drop-in replacements for their
scipy.ndimage counterparts (same signatures, defaults and results)::

    from mtcore import median_filter1d, uniform_filter1d, binomial_filter1d
"""

from .filters import MODES, binomial_filter1d, median_filter1d, pascal_weights, uniform_filter1d

__all__ = ["MODES", "binomial_filter1d", "median_filter1d", "pascal_weights", "uniform_filter1d"]
