"""Shared fixtures: the product's FMUs and SSPs, built (incrementally) once per session."""
import os
from pathlib import Path
import sys

import pytest

# pythonfmu's builder must come from the installed package: a pythonfmu FMU run in this process
# puts its own bundled copy (without the binaries the builder packs) on the import path.


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


_exit_status = {}


def pytest_sessionfinish(session, exitstatus):
    _exit_status["status"] = int(exitstatus)


def pytest_unconfigure(config):
    """Leave without the interpreter's teardown once pytest has reported.

    pythonfmu's native side can call a logger callback that Python already freed while the
    interpreter shuts down (seen here as an intermittent "corrupted double-linked list" abort
    after all tests passed, from FMU instances fmpy.simulate_fmu created and dropped). Every
    result is reported by now, so skip that teardown and keep pytest's own exit status."""
    if "status" in _exit_status:
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(_exit_status["status"])
