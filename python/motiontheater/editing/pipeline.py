"""Pipelines of steps, applied in order, and their TOML recipes (the CS838 "interpolator stack").

A recipe lists registered steps (``motiontheater steps`` prints them with
their options), each as a ``[[step]]`` table naming the step with ``run``
and giving its options; ``frames = [A, B]`` confines a step to frames A..B.
An exporter (``positions``) may come last.  Paths are relative to the
recipe's folder::

    [[step]]
    run = "median3"
    frames = [1, 300]

    [[step]]
    run = "slerp"
    frames = [100, 150]
    joints = ["lfemur", "rfemur"]

    [[step]]
    run = "binomial"
    size = 5
    frames = [200, 260]
"""

from __future__ import annotations

import math
import os
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .._io import read_source
from ..model.motion import Motion
from ..model.registry import Step, StepError, lookup

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib


@dataclass(frozen=True)
class Entry:
    """A step of a pipeline: its registered name and the options given (checked)."""

    name: str
    options: tuple[tuple[str, Any], ...] = ()

    @property
    def step(self) -> Step:
        """The registered step."""
        return lookup(self.name)

    def apply(self, motion: Motion) -> Motion:
        """The motion after this step."""
        return self.step(motion, **dict(self.options))


@dataclass(frozen=True)
class Pipeline:
    """Steps applied in order, each to the result of the one before; the inputs are never modified.

    ``Pipeline().then("median3", frames=(1, 300)).then("slerp", frames=(100, 150))``.
    ``whole_frames``: the takes it is applied to are read for the frames their files hold whole,
    where a file breaks off or goes on past its header (what ``motiontheater check`` finds as
    kind "header"; :func:`~motiontheater.formats.table.read_take_frames`), so that what is
    written is whole; a recipe says ``whole_frames = true``.
    """

    entries: tuple[Entry, ...] = ()
    whole_frames: bool = False

    def then(self, name: str, **options: Any) -> Pipeline:
        """This pipeline with the step ``name`` added (its options checked now; StepError if wrong)."""
        if self.exporter is not None:
            raise StepError(f"nothing can follow the exporter '{self.exporter.name}'")
        step = lookup(name)
        bound = step.bind(options)
        defaults = {o.name: o.default for o in step.all_options}
        # an option given as None where None is its default says nothing (and TOML has no None)
        given = tuple((key, bound[key]) for key in options if not (bound[key] is None and defaults[key] is None))
        return Pipeline((*self.entries, Entry(name, given)), self.whole_frames)

    @property
    def exporter(self) -> Entry | None:
        """The last entry if it writes a file (an exporter), else None."""
        return self.entries[-1] if self.entries and self.entries[-1].step.is_exporter else None

    @property
    def steps(self) -> tuple[Entry, ...]:
        """The entries that transform the motion (all but an exporter)."""
        return self.entries[:-1] if self.exporter is not None else self.entries

    def apply(self, motion: Motion) -> Motion:
        """The motion after every step (an exporter, if last, is not run: see :meth:`write`)."""
        for entry in self.steps:
            motion = entry.apply(motion)
        return motion

    def convention(self, convention: str) -> str:
        """The skeleton convention of the result on a motion of ``convention`` (``"asf"``, ``"bvh"``)."""
        for entry in self.steps:
            convention = entry.step.result_convention(convention, dict(entry.options))
        return convention

    def write(self, motion: Motion, target: str | os.PathLike) -> None:
        """Run the pipeline's exporter on ``motion`` (already through :meth:`apply`) into ``target``."""
        if self.exporter is None:
            raise StepError("the pipeline has no exporter")
        self.exporter.step(motion, target, **dict(self.exporter.options))

    def to_toml(self) -> str:
        """The recipe text of this pipeline; :meth:`from_toml` reads it back to an equal pipeline."""
        blocks = ["whole_frames = true\n"] if self.whole_frames else []
        for entry in self.entries:
            lines = ["[[step]]", f"run = {toml_value(entry.name)}"]
            lines += [f"{key} = {toml_value(value)}" for key, value in entry.options]
            blocks.append("\n".join(lines) + "\n")
        return "\n".join(blocks)

    @classmethod
    def from_toml(cls, text: str, where: str = "recipe", folder: str | os.PathLike = ".") -> Pipeline:
        """The pipeline of recipe text; ``where`` names it in messages, ``folder`` anchors its paths."""
        try:
            recipe = tomllib.loads(text)
        except tomllib.TOMLDecodeError as e:
            raise StepError(f"{where}: not a valid TOML recipe: {e}") from None
        unknown = sorted(set(recipe) - {"step", "whole_frames"})
        if unknown or not isinstance(recipe.get("step", []), list):
            raise StepError(
                f"{where}: a recipe holds [[step]] tables and whole_frames = true only, found {', '.join(unknown)}"
            )
        whole = recipe.get("whole_frames", False)
        if not isinstance(whole, bool):
            raise StepError(f"{where}: whole_frames must be true or false, got {whole!r}")
        pipeline = cls(whole_frames=whole)
        for n, table in enumerate(recipe.get("step", []), start=1):
            if not isinstance(table.get("run"), str):
                raise StepError(f'{where}: step {n} needs run = "<step name>"')
            options = {key: value for key, value in table.items() if key != "run"}
            try:
                step = lookup(table["run"])
                paths = {o.name for o in step.all_options if o.kind == "path"}
                options = {k: Path(folder, v) if k in paths and isinstance(v, str) else v for k, v in options.items()}
                pipeline = pipeline.then(table["run"], **options)
            except StepError as e:
                raise StepError(f"{where}: step {n}: {e}") from None
        return pipeline

    @classmethod
    def read(cls, path: str | os.PathLike) -> Pipeline:
        """The pipeline of a recipe file."""
        data, _ = read_source(path)  # a regular file: a FIFO or a device is refused, not waited on
        return cls.from_toml(_text(data, path), os.fspath(path), Path(path).parent)

    @classmethod
    def of(cls, name: str, **options: Any) -> Pipeline:
        """A pipeline of one step."""
        return cls().then(name, **options)


def toml_value(value: Any) -> str:
    """A TOML value for an option's value (text, number, bool, path, or a list of them)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return repr(value) if math.isfinite(value) else _nonfinite(value)
    if isinstance(value, (str, Path)):
        text = os.fspath(value)
        return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, (tuple, list)):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    raise TypeError(f"cannot write {value!r} to a recipe")


def _nonfinite(value: float) -> str:
    return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf")


def _text(data: bytes, path: str | os.PathLike) -> str:
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as e:
        raise ValueError(f"{os.fspath(path)}: a recipe is UTF-8 text; byte {e.start} is not") from None
