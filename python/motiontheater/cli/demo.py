"""The ``demo`` verb: the filters on a built-in noisy synthetic capture, against the clean one."""

from __future__ import annotations

import argparse
import time

import numpy as np

import mtcore

from ..editing.filtering import FILTERS
from .examples import noisy_rotations
from .verb import Verb


def _arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--size", type=int, default=5, help="filter window in frames (default 5)")
    parser.add_argument("--seconds", type=float, default=10.0, help="length of the capture (default 10)")
    parser.add_argument("--seed", type=int, default=0, help="random seed of the synthetic data")


def _demo(args: argparse.Namespace) -> int:
    clean, noisy = noisy_rotations(seconds=args.seconds, seed=args.seed)
    frames, channels = noisy.shape
    print(
        f"Synthetic capture: {frames} frames at 120 Hz x {channels} rotation channels (degrees),\n"
        f"Gaussian jitter of 1.5 deg and single-frame spikes of 20-40 deg on 0.5% of samples.\n"
        f"Filters of size {args.size} along the frames, edge mode 'nearest'.\n"
    )
    rows = [("unfiltered", noisy, 0.0)]
    for name, fn in FILTERS.items():
        start = time.perf_counter()
        out = fn(noisy, args.size, axis=0, mode="nearest")
        rows.append((name, out, time.perf_counter() - start))
    start = time.perf_counter()
    chained = mtcore.binomial_filter1d(
        mtcore.median_filter1d(noisy, args.size, axis=0, mode="nearest"), args.size, axis=0, mode="nearest"
    )
    rows.append(("median, then binomial", chained, time.perf_counter() - start))

    print("| filter | RMS error (deg) | max error (deg) | samples off by > 5 deg | time |")
    print("|---|---:|---:|---:|---:|")
    for name, values, seconds in rows:
        err = np.abs(values - clean)
        rms = float(np.sqrt(np.mean(err**2)))
        timing = f"{seconds * 1e6:.0f} us" if seconds else "-"
        print(f"| {name} | {rms:.3f} | {float(err.max()):.2f} | {int((err > 5).sum())} | {timing} |")
    return 0


DEMO = Verb(
    "demo",
    "smooth a built-in noisy synthetic 120 Hz capture and compare the filters",
    _arguments,
    _demo,
    description=(
        "Make a synthetic 120 Hz capture (90 rotation channels, the thesis's scene), add "
        "jitter and marker-pop spikes, smooth it with each filter and print how close each "
        "result comes to the clean motion."
    ),
    epilog="Example: motiontheater demo --seconds 2 --size 7",
)
