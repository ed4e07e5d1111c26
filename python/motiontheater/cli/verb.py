"""A verb of the command line: its name, its help, the arguments it takes and what runs it."""

from __future__ import annotations

import argparse
import re
import shutil
import textwrap
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class Verb:
    """``motiontheater NAME ...``: ``arguments(parser)`` adds its arguments, ``run(args)`` does
    the work and returns the exit status.  The description is filled to the terminal unless
    ``laid_out`` (one made with :func:`prose` beside a recipe's text); the epilog is kept line for
    line: its ``Example:`` lines are commands to paste, one a line."""

    name: str
    help: str
    arguments: Callable[[argparse.ArgumentParser], None]
    run: Callable[[argparse.Namespace], int]
    description: str | None = None
    epilog: str | None = None
    aliases: tuple[str, ...] = ()
    laid_out: bool = False

    def add_to(self, verbs: Any) -> None:
        """Add the verb's parser to ``verbs`` (what ``add_subparsers`` returned)."""
        description = self.description if self.laid_out or self.description is None else prose(self.description)
        parser = verbs.add_parser(
            self.name,
            aliases=list(self.aliases),
            help=self.help,
            description=description,
            epilog=self.epilog,
            formatter_class=argparse.RawDescriptionHelpFormatter,  # an example is a line to paste, unwrapped
        )
        self.arguments(parser)
        parser.set_defaults(run=self.run)


class VerbParser(argparse.ArgumentParser):
    """A verb's parser: its arguments in any order (``median TAKE --size 5 OUT``, which argparse
    alone rejects: it gives the optional OUT nothing when an option follows TAKE), and a word it
    does not know reported with the verb's usage, not the command's."""

    _parsing = False

    def parse_known_args(self, args: Any = None, namespace: Any = None) -> Any:
        """The verb's arguments, positionals and options intermixed; an unknown one is an error here."""
        if self._parsing:  # parse_known_intermixed_args parses in two passes through here
            return super().parse_known_args(args, namespace)
        self._parsing = True
        try:
            parsed, extras = self.parse_known_intermixed_args(args, namespace)
        finally:
            self._parsing = False
        if extras:
            self.error(f"unrecognized arguments: {' '.join(extras)}")
        return parsed, extras


def prose(*paragraphs: str, flags: Mapping[str, str] | None = None) -> str:
    """Paragraphs filled to the terminal's width, as :func:`plain` text (``flags`` as there), for
    --help texts that also hold examples."""
    width = min(shutil.get_terminal_size().columns, 100) - 2
    filled = (textwrap.fill(" ".join(plain(p, flags).split()), width) for p in paragraphs if p.strip())
    return "".join(f + "\n\n" for f in filled)


_ROLE = re.compile(r":[a-z]+:`~?(?:[\w.]*\.)?([^`.]+)`")  # :func:`~motiontheater.x.name` -> name
_RETURNS = re.compile(r"(^|[.:]\s+)Returns\b[^.]*\.\s*")


def plain(text: str, flags: Mapping[str, str] | None = None) -> str:
    """Docstring text as --help shows it (step summaries, descriptions and options come from
    docstrings): roles (:func:`name`) and literals (``x``) as their bare words, an option named as
    a literal as its flag (``max_gap`` -> --max-gap, by ``flags``), and no "Returns ..." sentence,
    which speaks of the Python function, not of the command."""
    for name, flag in (flags or {}).items():
        text = text.replace(f"``{name}``", flag)
    return _RETURNS.sub(r"\1", _ROLE.sub(r"\1", text).replace("``", ""))
