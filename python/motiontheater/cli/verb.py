"""A verb of the command line: its name, its help, the arguments it takes and what runs it."""

from __future__ import annotations

import argparse
import shutil
import textwrap
from collections.abc import Callable
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


def prose(*paragraphs: str) -> str:
    """Paragraphs filled to the terminal's width, for --help texts that also hold examples."""
    width = min(shutil.get_terminal_size().columns, 100) - 2
    return "".join(textwrap.fill(" ".join(p.split()), width) + "\n\n" for p in paragraphs if p.strip())
