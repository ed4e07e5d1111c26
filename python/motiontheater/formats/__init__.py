"""Formats: one codec module per file format and the table that maps a suffix to them.

``table`` is the one place that knows which suffix is which format (reader, writer,
skeleton file, convention); everything that reads or writes a take by its file name asks it.
"""

from .table import read_take, skeleton_for, take_suffix, write_take

__all__ = ["read_take", "skeleton_for", "take_suffix", "write_take"]
