"""Where the real captures are, for tests and benchmarks alike: beside the checkout (never in
it), ``../shared/data``; the environment variable MOTIONTHEATER_DATA overrides."""

import os
from pathlib import Path

DATA = Path(os.environ.get("MOTIONTHEATER_DATA", Path(__file__).resolve().parents[2] / "shared" / "data"))


def real_files(pattern: str) -> list[Path]:
    """Files of the corpus for parametrize; empty (the tests then skip) when it is absent."""
    return sorted(DATA.glob(pattern)) if DATA.is_dir() else []


def ids(paths):
    return [p.name for p in paths]
