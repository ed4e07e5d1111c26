"""The one registry of steps: every operation on a motion, registered once.

A *step* is a function ``f(motion, *, options...) -> Motion`` that returns a
new motion; an *exporter* is a function ``f(motion, target, *, options...)``
that writes a file.  Registering one with :func:`step` or :func:`exporter`
makes it, at once, a method (``motion.<name>(...)``), a command-line verb (``motiontheater <name>``), a
:class:`~motiontheater.editing.pipeline.Pipeline` step, a TOML recipe entry
(``[[step]] run = "<name>"``) and a batch step (``motiontheater batch
--recipe``).  Options are the function's keyword-only parameters, each
annotated ``Annotated[type, "help text"]``; the types below are understood
on the command line and in recipes.

This module is the package's bottom floor: it imports nothing from it, so
that :class:`~motiontheater.model.motion.Motion` can reach the registry and every
operation can register into it without a cycle.
"""

from __future__ import annotations

import inspect
import types
import typing
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, Literal, Protocol, Union

if TYPE_CHECKING:
    import numpy as np

Joints = tuple[str, ...] | None
"""Joint names ("root" and bone names); None for all.  Command line: ``a,b``; recipes: an array."""
Frames = tuple[int, int] | None
"""A range of frame numbers, first and last included.  Command line: ``A:B``; recipes: ``[A, B]``."""

REQUIRED: Any = inspect.Parameter.empty
RANGE_MODES = ("splice", "own", "none")


class Streamer(Protocol):
    """What a streamable step builds to go through a take of any length in chunks, to the same
    bytes as the step applied to the whole take.

    A step is streamable when it registers ``streamer``, a callable
    ``streamer(skeleton, **options) -> Streamer`` taking the step's options but ``frames`` (a
    streamed step runs over the whole take).  The driver
    (:func:`motiontheater.editing.streaming.stream`) then makes two passes over the take's frames
    in pieces of any size:

    1. ``summary = survey(piece, summary)`` for each piece in order, from ``summary=None``: what
       the step needs to know of the whole take (the smoothing filters: each channel's range and
       first value);
    2. ``prepared, state = prepare(piece, state)`` for each piece in order, from ``state=None``:
       the sequential part, carrying its state from piece to piece (the filters: angles
       unwrapped, whole turns counted);
    3. ``process(chunk, summary)`` on chunks of prepared frames that start at a multiple of
       ``block`` frames and carry ``halo`` frames of their neighbours before and after: its
       result is exact for the frames at least ``halo`` from either end of the chunk (unless that
       end is the take's), and the driver keeps those.
    """

    @property
    def halo(self) -> int:
        """Frames on either side of a frame that its result depends on."""
        ...

    @property
    def block(self) -> int:
        """Chunks that start at multiples of this frame count give the bytes of the whole take."""
        ...

    def survey(self, values: np.ndarray, summary: Any | None) -> Any:
        """The summary of the take so far, ``values`` (its next frames) added."""
        ...

    def prepare(self, values: np.ndarray, state: Any | None) -> tuple[np.ndarray, Any]:
        """(the frames prepared, the state after them); ``state`` is what the frames before left."""
        ...

    def process(self, prepared: np.ndarray, summary: Any) -> np.ndarray:
        """The step's result for a chunk of prepared frames (all channels)."""
        ...


class StepError(ValueError):
    """A step that does not exist, or options it does not take."""


@dataclass(frozen=True)
class Option:
    """One keyword option of a step: its name, what it holds, its default and help."""

    name: str
    kind: str  # int, float, str, bool, choice, ints, floats, names, path, frames
    default: Any
    help: str
    choices: tuple[Any, ...] = ()
    optional: bool = False  # None is a value

    @property
    def required(self) -> bool:
        """Whether the option has no default."""
        return self.default is REQUIRED

    @property
    def flag(self) -> str:
        """The command-line flag: --name-with-dashes."""
        return "--" + self.name.replace("_", "-")

    @property
    def metavar(self) -> str | None:
        """How the flag's value is shown in --help."""
        return {
            "int": "N",
            "float": "X",
            "ints": "N,N,...",
            "floats": "X,X,...",
            "names": "A,B,...",
            "path": "FILE",
            "frames": "A:B",
            "str": "TEXT",
        }.get(self.kind)

    def parse(self, text: str) -> Any:
        """The value of the command-line text ``text`` (argparse calls this; ValueError names the flag)."""
        try:
            return self.check(_from_text(self.kind, text, self.choices))
        except (TypeError, ValueError) as e:
            raise ValueError(f"{self.flag}: {e}") from None

    def check(self, value: Any) -> Any:
        """``value`` (from Python, a recipe or :meth:`parse`) in this option's canonical form, or
        ValueError saying what was expected."""
        if value is None and (self.optional or self.default is None):
            return None
        kind = self.kind
        if kind == "bool":
            if not isinstance(value, bool):
                raise ValueError(f"{self.name} must be true or false, got {value!r}")
            return value
        if kind in ("int", "float"):
            return _scalar(kind, value, self.name)
        if kind in ("ints", "floats"):
            items = (value,) if isinstance(value, (int, float)) and not isinstance(value, bool) else value
            if isinstance(items, (str, bytes)) or not isinstance(items, (list, tuple)) or not items:
                raise ValueError(f"{self.name} must be one or more numbers, got {value!r}")
            return tuple(_scalar(kind[:-1], item, self.name) for item in items)
        if kind == "names":
            items = (value,) if isinstance(value, str) else value
            if not isinstance(items, (list, tuple)) or not all(isinstance(i, str) and i for i in items):
                raise ValueError(f"{self.name} must be a list of names, got {value!r}")
            return tuple(items)
        if kind == "frames":
            if isinstance(value, str):
                return _from_text("frames", value, ())
            if not isinstance(value, (list, tuple)) or len(value) != 2:
                raise ValueError(f"{self.name} must be two frame numbers (first, last), got {value!r}")
            first, last = (_scalar("int", v, self.name) for v in value)
            if first > last:
                raise ValueError(f"{self.name}: the first frame {first} comes after the last {last}")
            return (first, last)
        if kind == "path":
            if not isinstance(value, (str, Path)):
                raise ValueError(f"{self.name} must be a file name, got {value!r}")
            return Path(value)
        if kind == "choice":
            if value not in self.choices:
                raise ValueError(f"{self.name} must be one of {', '.join(map(str, self.choices))}, got {value!r}")
            return value
        if not isinstance(value, str):
            raise ValueError(f"{self.name} must be text, got {value!r}")
        return value


def _scalar(kind: str, value: Any, name: str) -> Any:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f"{name} must be a number, got {value!r}")
    if kind == "int":
        if value != int(value):
            raise ValueError(f"{name} must be a whole number, got {value!r}")
        return int(value)
    return float(value)


def _from_text(kind: str, text: str, choices: tuple[Any, ...]) -> Any:
    """A command-line word as the value of an option of ``kind``."""
    if kind == "int":
        return int(text)
    if kind == "float":
        return float(text)
    if kind in ("ints", "floats"):
        convert = int if kind == "ints" else float
        return tuple(convert(item) for item in text.split(","))
    if kind == "names":
        names = tuple(name.strip() for name in text.split(","))
        if not all(names):
            raise ValueError(f"expected comma-separated names, got {text!r}")
        return names
    if kind == "frames":
        first, sep, last = text.partition(":")
        if not sep:
            raise ValueError(f"expected a frame range FIRST:LAST, got {text!r}")
        return (int(first), int(last))
    if kind == "path":
        return Path(text)
    if kind == "bool":
        lowered = text.lower()
        if lowered not in ("true", "false", "yes", "no", "1", "0"):
            raise ValueError(f"expected true or false, got {text!r}")
        return lowered in ("true", "yes", "1")
    if kind == "choice":
        return next((c for c in choices if str(c) == text), text)
    return text


@dataclass(frozen=True)
class Step:
    """A registered operation: see the module docstring.

    ``frames`` says how a frame range applies: "splice" (the registry runs
    the step on frames A..B alone and splices the result back, the other
    frames bit-identical), "own" (the function takes ``frames`` itself), or
    "none" (no range: the step changes frames, rate or skeleton).
    ``streamer``, where set, makes the step streamable: it builds the
    :class:`Streamer` that applies the step chunk by chunk.
    ``dry_run``, where set, is ``f(motion, **options) -> str``: what the step
    would do to the motion, in words, with nothing done (its verb's --dry-run);
    it takes the step's options, and ``frames`` where the registry splices.
    ``convention``, where set, is ``f(convention, options) -> convention``: the skeleton
    convention of the step's result from its input's and its bound options (unset: the input's),
    so that batch knows every output's name before it writes any.
    """

    name: str
    function: Callable[..., Any]
    summary: str
    description: str
    options: tuple[Option, ...]
    frames: str = "splice"
    streamer: Callable[..., Streamer] | None = None
    suffixes: tuple[str, ...] = ()  # an exporter's file suffixes; empty for a step
    several: bool = False  # an exporter that writes several takes into one file
    aliases: tuple[str, ...] = ()  # other names of the step (command-line verbs, recipes)
    dry_run: Callable[..., str] | None = None
    convention: Callable[[str, dict[str, Any]], str] | None = None

    def result_convention(self, convention: str, options: Mapping[str, Any]) -> str:
        """The skeleton convention of the step's result on a motion of ``convention``."""
        return convention if self.convention is None else self.convention(convention, self.bind(options))

    @property
    def is_exporter(self) -> bool:
        """Whether this writes a file (an exporter) rather than returning a motion."""
        return bool(self.suffixes)

    @property
    def all_options(self) -> tuple[Option, ...]:
        """The options a caller may give: the function's, and ``frames`` where the registry splices."""
        if self.frames == "splice":
            return (*self.options, FRAMES_OPTION)
        return self.options

    def bind(self, options: Mapping[str, Any]) -> dict[str, Any]:
        """The options checked and completed with defaults; StepError names an unknown or missing one."""
        known = {o.name: o for o in self.all_options}
        unknown = sorted(set(options) - set(known))
        if unknown:
            takes = ", ".join(known) or "no options"
            raise StepError(f"step '{self.name}' has no option {', '.join(map(repr, unknown))} (it takes {takes})")
        bound = {}
        for name, option in known.items():
            if name in options:
                try:
                    bound[name] = option.check(options[name])
                except ValueError as e:
                    raise StepError(f"step '{self.name}': {e}") from None
            elif option.required:
                raise StepError(f"step '{self.name}' needs the option {name!r}: {option.help}")
            else:
                bound[name] = option.default
        return bound

    def describe(self, motion: Any, **options: Any) -> str:
        """What the step would do to ``motion`` with ``options``, in words: its ``dry_run`` called
        with the options checked and completed as :meth:`bind` does; StepError for a step without
        one, or options it does not take."""
        if self.dry_run is None:
            raise StepError(f"step '{self.name}' has no dry run")
        return self.dry_run(motion, **self.bind(options))

    def __call__(self, motion: Any, *args: Any, **options: Any) -> Any:
        """Run the step on ``motion`` (exporters take the target as ``args[0]``)."""
        bound = self.bind(options)
        frames = bound.pop("frames", None) if self.frames == "splice" else None
        if frames is None:
            return self.function(motion, *args, **bound)
        return motion.splice(self.function(motion.crop(*frames), *args, **bound))


FRAMES_OPTION = Option("frames", "frames", None, "apply to frames FIRST..LAST only (frame numbers; default: all)")

_REGISTRY: dict[str, Step] = {}


_ALIASES: dict[str, str] = {}


def lookup(name: str) -> Step:
    """The step or exporter registered as ``name`` (or an alias); StepError lists the known ones otherwise."""
    try:
        return _REGISTRY[_ALIASES.get(name, name)]
    except KeyError:
        raise StepError(f"no step {name!r}; the steps are: {', '.join(sorted(_REGISTRY))}") from None


def steps() -> dict[str, Step]:
    """Every registered step and exporter by name, in the order they were registered."""
    return dict(_REGISTRY)


def step(
    name: str,
    summary: str | None = None,
    *,
    frames: str = "splice",
    streamer: Callable[..., Any] | None = None,
    aliases: tuple[str, ...] = (),
    dry_run: Callable[..., str] | None = None,
    convention: Callable[[str, dict[str, Any]], str] | None = None,
) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """Register the decorated function as the step ``name`` (see the module docstring and
    :class:`Step` for ``frames``, ``streamer``, ``dry_run`` and ``convention``)."""

    def decorate(function: Callable[..., Any]) -> Callable[..., Any]:
        register(
            name,
            function,
            summary,
            frames=frames,
            streamer=streamer,
            aliases=aliases,
            dry_run=dry_run,
            convention=convention,
        )
        return function

    return decorate


def exporter(
    name: str, suffixes: tuple[str, ...], summary: str | None = None, *, several: bool = False
) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """Register the decorated ``f(motion, target, *, options...)`` as the exporter ``name`` writing
    ``suffixes``; ``several``: it also takes a sequence of motions, all into one file (its verb
    then reads every take it is given)."""
    if not suffixes:
        raise ValueError("an exporter writes at least one file suffix")

    def decorate(function: Callable[..., Any]) -> Callable[..., Any]:
        register(name, function, summary, frames="none", suffixes=tuple(s.lower() for s in suffixes), several=several)
        return function

    return decorate


def register(
    name: str,
    function: Callable[..., Any],
    summary: str | None = None,
    *,
    frames: str = "splice",
    streamer: Callable[..., Any] | None = None,
    suffixes: tuple[str, ...] = (),
    several: bool = False,
    fixed: Mapping[str, Any] | None = None,
    aliases: tuple[str, ...] = (),
    dry_run: Callable[..., str] | None = None,
    convention: Callable[[str, dict[str, Any]], str] | None = None,
) -> Step:
    """Register ``function`` as ``name``; ``fixed`` options are bound and hidden (one function serving
    several steps, e.g. each filter kind).  Returns the step; a name registered twice is an error."""
    if frames not in RANGE_MODES:
        raise ValueError(f"frames must be one of {RANGE_MODES}, got {frames!r}")
    for word in (name, *aliases):
        if not word.replace("_", "").isalnum() or not word[0].isalpha():
            raise ValueError(f"a step name is a word of letters, digits and '_', got {word!r}")
        if word in _REGISTRY or word in _ALIASES:
            raise ValueError(f"a step {word!r} is registered already (by {lookup(word).function.__module__})")
    fixed = dict(fixed or {})
    options = tuple(o for o in _options(function) if o.name not in fixed)
    if frames == "own" and "frames" not in {o.name for o in options}:
        raise ValueError(f"step {name!r} takes its own frame range but has no 'frames' option")
    doc = inspect.cleandoc(function.__doc__ or "")
    first, _, rest = doc.partition("\n\n")
    run = function if not fixed else _bound(function, fixed)
    registered = Step(
        name=name,
        function=run,
        summary=summary or " ".join(first.split()),
        description=rest,
        options=options,
        frames=frames,
        streamer=streamer,
        suffixes=suffixes,
        several=several,
        aliases=aliases,
        dry_run=dry_run,
        convention=convention,
    )
    _REGISTRY[name] = registered
    _ALIASES.update((alias, name) for alias in aliases)
    return registered


def unregister(name: str) -> None:
    """Forget a step and its aliases (for tests that register a toy one)."""
    gone = _REGISTRY.pop(name, None)
    for alias in gone.aliases if gone else ():
        _ALIASES.pop(alias, None)


def _bound(function: Callable[..., Any], fixed: Mapping[str, Any]) -> Callable[..., Any]:
    def run(*args: Any, **options: Any) -> Any:
        return function(*args, **options, **fixed)

    run.__name__ = function.__name__
    run.__module__ = function.__module__
    return run


def _options(function: Callable[..., Any]) -> list[Option]:
    """The options of a step function: its keyword-only parameters and their annotations."""
    hints = typing.get_type_hints(function, include_extras=True)
    options = []
    for parameter in inspect.signature(function).parameters.values():
        if parameter.kind is not inspect.Parameter.KEYWORD_ONLY:
            continue
        hint = hints.get(parameter.name)
        if typing.get_origin(hint) is not Annotated:
            raise TypeError(
                f"{function.__qualname__}: option {parameter.name!r} needs an Annotated[type, 'help'] annotation"
            )
        base, help_text = typing.get_args(hint)[:2]
        kind, choices, optional = _kind(base, f"{function.__qualname__}: option {parameter.name!r}")
        options.append(Option(parameter.name, kind, parameter.default, str(help_text), choices, optional))
    return options


_KINDS = {int: "int", float: "float", str: "str", bool: "bool", Path: "path"}


def _kind(hint: Any, where: str) -> tuple[str, tuple[Any, ...], bool]:
    """(kind, choices, None allowed) of an option's type."""
    origin, args = typing.get_origin(hint), typing.get_args(hint)
    if origin in (Union, types.UnionType) and type(None) in args:
        rest = [a for a in args if a is not type(None)]
        if len(rest) == 1:
            kind, choices, _ = _kind(rest[0], where)
            return kind, choices, True
    if hint in _KINDS:
        return _KINDS[hint], (), False
    if origin is Literal:
        return "choice", args, False
    if origin is tuple:
        if args == (str, Ellipsis):
            return "names", (), False
        if args in ((int, Ellipsis), (float, Ellipsis)):
            return ("ints" if args[0] is int else "floats"), (), False
        if args == (int, int):
            return "frames", (), False
    raise TypeError(f"{where}: the registry cannot read options of type {hint!r}")


def is_step(name: str) -> bool:
    """Whether ``name`` is a registered step (not an exporter): what ``motion.<name>(...)`` runs."""
    found = _REGISTRY.get(_ALIASES.get(name, name))
    return found is not None and not found.is_exporter
