"""The ``motiontheater`` command: a verb per registered step, and the verbs over files and
databases (info, convert, combine, batch, view, bench, ...)."""

from .command import build_parser, main

__all__ = ["build_parser", "main"]
