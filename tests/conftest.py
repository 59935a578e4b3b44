"""Shared fixtures: the product's FMUs and SSPs, built (incrementally) once per session."""
import ctypes
from pathlib import Path

from fmpy.fmi1 import printLogMessage
from fmpy.fmi2 import fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
from fmpy.logging import addLoggerProxy
import pytest

# FMPy routes the messages of every FMU instance that uses its logger proxy (the default one
# included) to the Python logger registered last (one global in its logging library). A test that
# passes a logger of its own to fmpy.simulate_fmu leaves that global pointing at a callback that
# is gone once the call returns, and the next FMU message crashes the process. After every test
# the global is pointed at a logger that lives as long as the session.
_FMPY_CALLBACKS = fmi2CallbackFunctions()
_FMPY_LOGGER = fmi2CallbackLoggerTYPE(printLogMessage)


@pytest.fixture(autouse=True)
def fmpy_logger_alive():
    yield
    _FMPY_CALLBACKS.logger = _FMPY_LOGGER  # addLoggerProxy swaps it for its proxy: set it again
    addLoggerProxy(ctypes.byref(_FMPY_CALLBACKS))


@pytest.fixture(scope="session")
def built():
    """(fmu paths by name, ssp paths by system name) from build_fmus.build_all()."""
    import build_fmus

    fmus, ssps = build_fmus.build_all(verbose=False)
    return {p.stem: p for p in fmus}, {p.stem: p for p in ssps}


@pytest.fixture(scope="session")
def build_one(tmp_path_factory):
    """build_one("neighbor_orbit.py") -> path of that one wrapper's FMU, built once per session
    into a private folder (for FMU tests that need no other FMU and no SSP)."""
    import build_fmus

    cache = {}

    def build(script_name):
        if script_name not in cache:
            dest = tmp_path_factory.mktemp(Path(script_name).stem)
            cache[script_name] = build_fmus.build_fmu(build_fmus.FMU_SOURCES / script_name, dest)
        return cache[script_name]

    return build


@pytest.fixture(scope="session")
def fmu_paths(built):
    return built[0]


@pytest.fixture(scope="session")
def ssp_paths(built):
    return built[1]
