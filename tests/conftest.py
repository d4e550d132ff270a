"""Shared fixtures. YADE tests are skipped with a clear reason where YADE cannot be imported."""
import os
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from grainfrac_yade.params import load_parameters  # noqa: E402


def yade_available() -> bool:
    try:
        from grainfrac_yade.engines.yade import load_yade
        load_yade()
        return True
    except Exception:
        return False


needs_yade = pytest.mark.skipif(not yade_available() and not os.environ.get("CI"),
                                reason="YADE not importable (run setup.sh)")


@pytest.fixture(scope="session")
def params():
    return load_parameters()


@pytest.fixture(scope="session")
def small_params():
    """10 x 20 mm specimen of the paper's granite, ~255 cells."""
    return load_parameters(overrides=["specimen.width=10e-3", "specimen.height=20e-3"])


@pytest.fixture
def rng():
    return np.random.default_rng(12345)


@pytest.fixture
def strict_floats():
    """Floating-point warnings (numpy and Python) raise inside the test."""
    with np.errstate(all="raise"), warnings.catch_warnings():
        warnings.simplefilter("error")
        yield
