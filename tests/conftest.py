"""Shared fixtures: the product's FMUs and SSPs, built (incrementally) once per session."""
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))


@pytest.fixture(scope="session")
def built():
    """(fmu paths by name, ssp paths by system name) from build_fmus.build_all()."""
    import build_fmus

    fmus, ssps = build_fmus.build_all(verbose=False)
    return {p.stem: p for p in fmus}, {p.stem: p for p in ssps}


@pytest.fixture(scope="session")
def fmu_paths(built):
    return built[0]


@pytest.fixture(scope="session")
def ssp_paths(built):
    return built[1]
