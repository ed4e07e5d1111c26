import os
import shutil
from pathlib import Path

import numpy as np
import pytest

from corpus import DATA

# The checkout whose own files (the header, the cffi build, the README, fuzz/) some tests read: the one
# around tests/, or MOTIONTHEATER_SOURCE for a copy of tests/ run against an installed wheel (.ci/wheel).
SOURCE = Path(os.environ.get("MOTIONTHEATER_SOURCE", Path(__file__).resolve().parents[1]))
NO_SOURCE = f"no source tree at {SOURCE}: the tests run outside a checkout (set MOTIONTHEATER_SOURCE to one)"
needs_source = pytest.mark.skipif(not (SOURCE / "csrc" / "mtcore.h").is_file(), reason=NO_SOURCE)


@pytest.fixture
def rng():
    return np.random.default_rng(20041122)


@pytest.fixture(scope="session")
def data_dir() -> Path:
    if not DATA.is_dir():
        pytest.skip(f"real capture corpus not found at {DATA} (set MOTIONTHEATER_DATA)")
    return DATA


@pytest.fixture
def copies(data_dir, tmp_path):
    """copies(folder, names): a folder of tmp_path holding copies of those files of the corpus's
    ``folder`` (a test that writes beside its inputs never touches the corpus)."""

    def made(folder: str, names) -> Path:
        target = tmp_path / folder
        target.mkdir(exist_ok=True)
        for name in names:
            shutil.copy(data_dir / folder / name, target / name)
        return target

    return made
