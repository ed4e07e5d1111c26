"""The ``motiontheater`` command line: the verbs, in the order ``--help`` lists them, and
:func:`main`.

Every registered step (see :mod:`motiontheater.model.registry`) is a verb of its own
(:mod:`.steps`); each other verb is a :class:`~.verb.Verb` in the module of what it does.
"""

from __future__ import annotations

import argparse
import logging
import os
import sys
import warnings
from collections.abc import Sequence

from .._signals import terminate_as_interrupt
from .._version import __version__
from . import feet, views
from .batch import BATCH
from .check import CHECK
from .combine import COMBINE
from .demo import DEMO
from .info import INFO
from .search import INDEX, SEARCH
from .steps import APPLY, FILTER, LISTING, step_verbs
from .timing import BENCH
from .verb import Verb, VerbParser


def verbs() -> list[Verb]:
    """Every verb: those of the modules here and one per registered step (as registered now)."""
    return [
        DEMO,
        LISTING,
        INFO,
        FILTER,
        APPLY,
        *step_verbs(),
        BATCH,
        CHECK,
        INDEX,
        SEARCH,
        COMBINE,
        *feet.VERBS,
        BENCH,
        *views.VERBS,
    ]


def build_parser() -> argparse.ArgumentParser:
    """The parser of every verb."""
    parser = argparse.ArgumentParser(
        prog="motiontheater",
        description=(
            "Clean, cut, splice and smooth motion-capture data (ASF/AMC and BVH). "
            "Run 'motiontheater demo' to smooth a built-in noisy 120 Hz capture; "
            "'motiontheater steps' lists every step and its options."
        ),
    )
    parser.add_argument("--version", action="version", version=f"motiontheater {__version__}")
    subparsers = parser.add_subparsers(dest="verb", metavar="<verb>", parser_class=VerbParser)
    for verb in verbs():
        verb.add_to(subparsers)
    return parser


class _Notes(logging.Handler):
    """Prints what steps note on the package's logger (a cut-off chosen, gaps left) to stderr,
    above batch's progress bar when one is drawn."""

    def emit(self, record: logging.LogRecord) -> None:
        from tqdm import tqdm  # here: most runs note nothing, and tqdm takes a while to import

        tqdm.write(self.format(record), file=sys.stderr)


def _notes() -> logging.Handler:
    handler = _Notes(logging.INFO)
    handler.setFormatter(logging.Formatter("%(message)s"))
    return handler


def _warning(message: Warning | str, *args: object, **kwargs: object) -> None:
    """A Python warning as the command line says it: ``warning: <text>``, without its file and line."""
    print(f"warning: {message}", file=sys.stderr)


def _naming_the_file(args: argparse.Namespace, text: str) -> str:
    """A failure's message, led by the take the verb read where it names none of the files given
    (a step's reason, such as a take of NaN having no feet, does not know its file)."""
    given = [v for value in vars(args).values() for v in (value if isinstance(value, list) else [value])]
    files = [v for v in given if isinstance(v, str) and os.path.splitext(v)[1]]
    take = next((getattr(args, name) for name in ("input", "take") if isinstance(getattr(args, name, None), str)), None)
    if take is None or any(f in text or os.path.basename(f) in text for f in files):
        return text
    return f"{take}: {text}"


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status: 0 done, 1 some takes failed (batch), 2 a
    one-line reason on failure, 130 interrupted (Ctrl-C or SIGTERM: nothing partial is left)."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.verb is None:
        parser.print_help()
        return 0
    logger, notes = logging.getLogger("motiontheater"), _notes()
    logger.addHandler(notes)
    level = logger.level
    logger.setLevel(logging.INFO)
    try:
        with terminate_as_interrupt(), warnings.catch_warnings():
            warnings.showwarning = _warning
            status = int(args.run(args))
        sys.stdout.flush()  # here, where a closed pipe is caught, not at exit
        return status
    except KeyboardInterrupt:
        print(f"motiontheater {args.verb}: interrupted; nothing was left half-written", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # the reader of our output went away (| head): say nothing more, to no one
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except MemoryError:
        print(f"motiontheater {args.verb}: not enough memory for this take", file=sys.stderr)
        return 2
    except (ValueError, TypeError, OSError, RuntimeError) as exc:
        text = _naming_the_file(args, str(exc)) if type(exc) is ValueError else str(exc)  # a step's reason
        print(f"motiontheater {args.verb}: {text}", file=sys.stderr)
        return 2
    finally:
        logger.removeHandler(notes)
        logger.setLevel(level)


if __name__ == "__main__":
    sys.exit(main())
