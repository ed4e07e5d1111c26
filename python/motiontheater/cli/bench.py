"""The thesis's filter timing table (24,000 values, 2004), measured again beside today's peers.

MotionTheater (2004) compared its C++ filters with a MEL script on a scene
of 30 joints x 267 frames x 3 rotation values at depth 3.  This module
times the same scene (synthetic, or the first 267 frames of a real take)
and a one-hour 120 Hz capture with mtcore, a plain Python loop (the
interpreted baseline, as MEL was), scipy.ndimage and bottleneck where
installed, and numpy's copy as the memory-bandwidth ceiling.
"""

from __future__ import annotations

import importlib
import json
import math
import time
from collections.abc import Callable
from functools import partial

import numpy as np

import mtcore

from ..editing.filtering import FILTERS
from .examples import noisy_rotations

THESIS_SCENE = (267, 90)
HOUR = (432_000, 62)
# Seconds per filter of the scene at depth 3: Hiller/Bomm's MEL script and MotionTheater's C++ (2004).
THESIS_2004 = {"mean": (1.99, 0.66), "binomial": (2.05, 0.64), "median": (2.08, 0.59)}
KINDS = ("mean", "binomial", "median")
OURS = FILTERS


def python_filter(kind: str, rows: list[list[float]], size: int) -> list[list[float]]:
    """The interpreted baseline: plain Python loops over channels and frames, edges held ("nearest")."""
    frames = len(rows)
    channels = len(rows[0]) if rows else 0
    half = size // 2
    weights = [math.comb(size - 1, k) / 2 ** (size - 1) for k in range(size)]
    out = [[0.0] * channels for _ in range(frames)]
    for c in range(channels):
        for t in range(frames):
            window = [rows[min(max(t + j - half, 0), frames - 1)][c] for j in range(size)]
            if kind == "median":
                out[t][c] = sorted(window)[half]
            elif kind == "mean":
                out[t][c] = sum(window) / size
            else:
                out[t][c] = sum(w * v for w, v in zip(weights, window))
    return out


def peers() -> dict[str, Callable | None]:
    """scipy.ndimage and bottleneck filters with mtcore's signature, or None where not installed."""
    found: dict[str, Callable | None] = {}
    try:
        ndi = importlib.import_module("scipy.ndimage")
        found["scipy"] = lambda kind, x, size: {
            "median": lambda: ndi.median_filter(x, size=size, axes=(0,), mode="nearest"),
            "mean": lambda: ndi.uniform_filter1d(x, size, axis=0, mode="nearest"),
            "binomial": lambda: ndi.correlate1d(x, mtcore.pascal_weights(size), axis=0, mode="nearest"),
        }[kind]()
    except ImportError:
        found["scipy"] = None
    try:
        bn = importlib.import_module("bottleneck")
        # Trailing windows with partial edges: a speed peer, not the same result.
        found["bottleneck"] = lambda kind, x, size: (
            bn.move_median(x, size, axis=0, min_count=1)
            if kind == "median"
            else bn.move_mean(x, size, axis=0, min_count=1)
            if kind == "mean"
            else None
        )
    except ImportError:
        found["bottleneck"] = None
    return found


def best_time(fn: Callable[[], object], repeat: int) -> float:
    """The fastest of ``repeat`` calls, in seconds: the figure least disturbed by other load."""
    best = math.inf
    for _ in range(repeat):
        start = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - start)
    return best


def scene_from_take(motion) -> np.ndarray:
    """The thesis-like scene from a real take: its first 267 frames, rotation channels only."""
    columns = [i for i, (_, dof) in enumerate(motion.channels) if dof.startswith("r")]
    return np.ascontiguousarray(motion.values[: THESIS_SCENE[0], columns])


def measure(
    scene: np.ndarray | None = None,
    source: str = "synthetic",
    hour_frames: int = HOUR[0],
    sizes=(3, 5, 7),
    repeat: int = 5,
) -> dict:
    """Time every filter on the scene and on a long capture; returns a JSON-ready report."""
    if scene is None:
        scene = noisy_rotations(seconds=THESIS_SCENE[0] / 120, channels=THESIS_SCENE[1])[1]
    available = peers()
    rows_of_scene = scene.tolist()
    scene_rows = []
    for kind in KINDS:
        for size in sizes:
            fresh = best_time(partial(OURS[kind], scene, size, axis=0, mode="nearest"), repeat * 20)
            slow_repeat = max(1, repeat // 2)
            row = {
                "filter": kind,
                "size": size,
                "mtcore": fresh,
                "python": best_time(partial(python_filter, kind, rows_of_scene, size), slow_repeat),
            }
            for name, peer in available.items():
                row[name] = (
                    None
                    if peer is None or peer(kind, scene, size) is None
                    else best_time(partial(peer, kind, scene, size), repeat * 4)
                )
            row["mel_2004"], row["cpp_2004"] = THESIS_2004[kind] if size == 3 else (None, None)
            scene_rows.append(row)

    hour = np.random.default_rng(0).standard_normal((hour_frames, HOUR[1])).cumsum(axis=0)
    out = np.empty_like(hour)
    copyto = best_time(lambda: np.copyto(out, hour), repeat)
    copy = best_time(hour.copy, repeat)
    hour_rows = []
    for kind in KINDS:
        for size in sizes:
            row = {
                "filter": kind,
                "size": size,
                "mtcore": best_time(partial(OURS[kind], hour, size, axis=0, mode="nearest"), repeat),
                "mtcore_output": best_time(partial(OURS[kind], hour, size, 0, out, mode="nearest"), repeat),
            }
            for name, peer in available.items():
                row[name] = (
                    None
                    if peer is None or peer(kind, hour[:10], size) is None
                    else best_time(partial(peer, kind, hour, size), max(2, repeat // 2))
                )
            hour_rows.append(row)
    return {
        "scene": {"source": source, "shape": list(scene.shape), "rows": scene_rows},
        "hour": {"shape": list(hour.shape), "copyto": copyto, "copy": copy, "rows": hour_rows},
        "peers": {name: peer is not None for name, peer in available.items()},
        "number_code": mtcore.text.number_code(),  # which code writes numbers here (the tables time filters)
    }


def _t(seconds: float | None) -> str:
    if seconds is None:
        return "-"
    if seconds >= 0.1:
        return f"{seconds:.2f} s"
    return f"{seconds * 1e3:.2f} ms" if seconds >= 1e-3 else f"{seconds * 1e6:.1f} µs"


def _x(numerator: float | None, denominator: float | None) -> str:
    return "-" if numerator is None or denominator is None else f"{numerator / denominator:,.0f}x"


def _duration(seconds: float) -> str:
    """A capture's length as its table's heading says it: "One hour", "3 minutes", "0.83 seconds"."""
    unit, length = ("hour", 3600) if seconds >= 3600 else ("minute", 60) if seconds >= 60 else ("second", 1)
    count = seconds / length
    return f"One {unit}" if count == 1 else f"{count:.2g} {unit}s"


def markdown(report: dict) -> str:
    """The report of :func:`measure` as Markdown tables, the thesis's table first."""
    scene, hour = report["scene"], report["hour"]
    frames, channels = scene["shape"]
    lines = [
        f"## The thesis scene: {frames} frames x {channels} rotation channels = {frames * channels:,} values "
        f"({scene['source']})",
        "",
        "| filter | size | MEL 2004 | C++ 2004 | C++ vs MEL | mtcore | Python loop | mtcore vs Python "
        "| scipy.ndimage | mtcore vs scipy | bottleneck | mtcore vs bottleneck |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in scene["rows"]:
        lines.append(
            f"| {r['filter']} | {r['size']} | {_t(r['mel_2004'])} | {_t(r['cpp_2004'])} | "
            f"{_x(r['mel_2004'], r['cpp_2004'])} | {_t(r['mtcore'])} | {_t(r['python'])} | "
            f"{_x(r['python'], r['mtcore'])} | {_t(r.get('scipy'))} | {_x(r.get('scipy'), r['mtcore'])} | "
            f"{_t(r.get('bottleneck'))} | {_x(r.get('bottleneck'), r['mtcore'])} |"
        )
    frames, channels = hour["shape"]
    lines += [
        "",
        f"## {_duration(frames / 120)} at 120 Hz: {frames:,} frames x {channels} channels "
        f"(numpy.copyto {_t(hour['copyto'])}, ndarray.copy {_t(hour['copy'])})",
        "",
        "| filter | size | mtcore | M values/s | share of copy (output=) | share of copy (fresh) "
        "| scipy.ndimage | mtcore vs scipy | bottleneck | mtcore vs bottleneck |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    values = frames * channels
    for r in hour["rows"]:
        lines.append(
            f"| {r['filter']} | {r['size']} | {_t(r['mtcore'])} | {values / r['mtcore'] / 1e6:,.0f} | "
            f"{hour['copyto'] / r['mtcore_output']:.0%} | {hour['copy'] / r['mtcore']:.0%} | {_t(r.get('scipy'))} | "
            f"{_x(r.get('scipy'), r['mtcore'])} | {_t(r.get('bottleneck'))} | {_x(r.get('bottleneck'), r['mtcore'])} |"
        )
    lines += ["", f"Numbers are written here by the {report['number_code']} code (mtcore.text.number_code())."]
    missing = [name for name, present in report["peers"].items() if not present]
    if missing:
        lines += ["", f'Not installed, so not measured: {", ".join(missing)} (pip install "motiontheater[bench]").']
    return "\n".join(lines)


def as_json(report: dict) -> str:
    """The report of :func:`measure` as JSON text."""
    return json.dumps(report, indent=2)
