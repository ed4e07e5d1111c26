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
    the work and returns the exit status.  ``laid_out`` keeps the description's line breaks (one
    made with :func:`prose` beside examples)."""

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
        layout = argparse.RawDescriptionHelpFormatter if self.laid_out else argparse.HelpFormatter
        parser = verbs.add_parser(
            self.name,
            aliases=list(self.aliases),
            help=self.help,
            description=self.description,
            epilog=self.epilog,
            formatter_class=layout,
        )
        self.arguments(parser)
        parser.set_defaults(run=self.run)


def prose(*paragraphs: str) -> str:
    """Paragraphs filled to the terminal's width, for --help texts that also hold examples."""
    width = min(shutil.get_terminal_size().columns, 100) - 2
    return "".join(textwrap.fill(" ".join(p.split()), width) + "\n\n" for p in paragraphs if p.strip())
