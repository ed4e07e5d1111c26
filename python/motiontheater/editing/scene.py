"""Scenes of tracks: motions laid one after another over a base motion, and their recipe files."""

from __future__ import annotations

import functools
import os
import sys
from dataclasses import dataclass, field, replace
from pathlib import Path

from .._io import read_source
from ..formats.table import read_take
from ..model.motion import Motion
from .combine import Plan, combine_planned

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

TRACK_OPTIONS = ("cut", "scale", "blend", "preserve", "joints", "discard_old", "interpolate", "rotation_blend", "up")


@dataclass(frozen=True)
class Track:
    """A motion and the :func:`~motiontheater.editing.combine.combine` options that lay it over the scene."""

    motion: Motion
    options: dict = field(default_factory=dict)
    name: str = ""


@dataclass(frozen=True)
class Scene:
    """A base motion and tracks applied over it in order (the thesis's MotionCombiner tracks).

    Scenes are values: :meth:`add` returns a new scene.  :meth:`render`
    combines every track into one Motion.
    """

    base: Motion
    tracks: tuple[Track, ...] = ()

    def add(self, motion: Motion, name: str = "", **options) -> Scene:
        """This scene with a track more: ``motion`` laid over it with :func:`~motiontheater.editing.combine.combine` ``options``."""
        unknown = set(options) - set(TRACK_OPTIONS)
        if unknown:
            raise ValueError(
                f"unknown track option(s) {', '.join(sorted(unknown))}; expected {', '.join(TRACK_OPTIONS)}"
            )
        return replace(self, tracks=(*self.tracks, Track(motion, dict(options), name)))

    def render(self, workers: int | None = None) -> Motion:
        """The motion of the base with every track applied in order."""
        steps = self._apply(workers)
        return steps[-1][2] if steps else self.base

    def plans(self) -> list[tuple[Track, Plan]]:
        """Each track's frame map, against the scene as it stands before it."""
        return [(track, p) for track, p, _ in self._apply(None)]

    def _apply(self, workers) -> list[tuple[Track, Plan, Motion]]:
        """(track, its frame map, the scene after it) for every track; errors name the track."""
        steps, result = [], self.base
        for n, track in enumerate(self.tracks, start=1):
            try:
                frame_map, result = combine_planned(result, track.motion, workers=workers, **track.options)
            except ValueError as e:
                raise ValueError(f"{track.name or f'track {n}'}: {e}") from None
            steps.append((track, frame_map, result))
        return steps


RECIPE_HELP = """\
A scene recipe is a TOML file: a [base] motion, then [[track]] tables laid over it in
order, each with its motion and the combiner's options (cut, scale, blend, preserve,
joints, discard_old, interpolate, rotation_blend, up).  Paths are relative to the
recipe; takes may be AMC (with the skeleton given, or found beside the base) or BVH.
For example, scene.toml:

  skeleton = "02.asf"            # optional: else the ASF beside the base motion
  frame_rate = 120               # optional: for AMCs that do not say
  [base]
  motion = "02_01.amc"
  [[track]]                      # the upper body of another take, slowed to 66 frames
  motion = "02_02.amc"
  joints = ["lowerback", "upperback", "thorax"]
  cut = [1, 55]
  scale = [1, 66]
  [[track]]                      # back to the base's own upper body, blended over 10 frames
  motion = "02_01.amc"
  joints = ["lowerback", "upperback", "thorax"]
  cut = [67, 113]
  blend = 10
"""


def read_recipe(path: str | os.PathLike) -> Scene:
    """A scene from a TOML recipe (see :data:`RECIPE_HELP` for its keys and an example).

    Errors name the recipe and the track at fault.
    """
    path = Path(path)
    data, _ = read_source(path)  # a regular file: a FIFO or a device is refused, not waited on
    try:
        recipe = tomllib.loads(data.decode("utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as e:
        raise ValueError(f"{path}: not a valid TOML recipe: {e}") from None
    folder = path.parent

    def where(name: str, key: str) -> Path:
        if not isinstance(name, str):
            raise ValueError(f"{path}: {key} must be a file name, got {name!r}")
        return folder / name

    base = recipe.get("base", {}).get("motion")
    if base is None:
        raise ValueError(f'{path}: the recipe needs [base] with motion = "FILE.amc"')
    base = where(base, "base.motion")
    skeleton = where(recipe["skeleton"], "skeleton") if "skeleton" in recipe else None
    rate = recipe.get("frame_rate")

    @functools.cache  # a take used by several tracks is read once; motions are read-only
    def motion(file: Path) -> Motion:
        return read_take(file, skeleton, frame_rate=rate)

    scene = Scene(motion(base))
    for n, track in enumerate(recipe.get("track", []), start=1):
        if "motion" not in track:
            raise ValueError(f'{path}: track {n} needs motion = "FILE.amc"')
        options = {k: v for k, v in track.items() if k != "motion"}
        try:
            scene = scene.add(
                motion(where(track["motion"], f"track {n} motion")), name=f"track {n} ({track['motion']})", **options
            )
        except ValueError as e:
            raise ValueError(f"{path}: track {n}: {e}") from None
    return scene
