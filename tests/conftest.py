from pathlib import Path

import numpy as np
import pytest

from corpus import DATA


@pytest.fixture
def rng():
    return np.random.default_rng(20041122)


@pytest.fixture(scope="session")
def data_dir() -> Path:
    if not DATA.is_dir():
        pytest.skip(f"real capture corpus not found at {DATA} (set MOTIONTHEATER_DATA)")
    return DATA
