"""Fixtures of the FMU tests: the C host with no Python in it, a Python with only numpy and fmpy."""
import os
from pathlib import Path
import subprocess
import venv

import fmpy
import numpy as np
import pytest

from paths import TESTS

HOST_SOURCES = TESTS / "fmus" / "c_host"


def compile_host(tmp_path_factory, source):
    """A C host of tests/fmus/c_host compiled outside the checkout; it has no Python in it."""
    out = tmp_path_factory.mktemp("c_host") / Path(source).stem
    headers = Path(fmpy.__file__).parent / "c-code"
    cmd = ["gcc", "-std=c99", "-O1", "-Wall", "-Werror", f"-I{headers}", str(HOST_SOURCES / source), "-o", str(out),
           "-ldl", "-lpthread"]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    libs = subprocess.run(["ldd", str(out)], capture_output=True, text=True).stdout
    assert "python" not in libs  # the host itself has no Python
    return out


@pytest.fixture(scope="session")
def c_host(tmp_path_factory):
    return compile_host(tmp_path_factory, "fmu_host.c")


@pytest.fixture(scope="session")
def threaded_host(tmp_path_factory):
    """tests/fmus/c_host/threaded_host.c: many instances from a pthread pool."""
    return compile_host(tmp_path_factory, "threaded_host.c")


@pytest.fixture(scope="session")
def fuzz_host(tmp_path_factory):
    """tests/fmus/c_host/fuzz_host.c: call sequences from a seed, checked against the standard."""
    return compile_host(tmp_path_factory, "fuzz_host.c")


@pytest.fixture(scope="session")
def numpy_only_python(tmp_path_factory):
    """A fresh virtual environment with fmpy and numpy and nothing else of ours."""
    env_dir = tmp_path_factory.mktemp("numpy_only") / "venv"
    venv.EnvBuilder(with_pip=True).create(env_dir)
    python = env_dir / ("Scripts" if os.name == "nt" else "bin") / "python"
    numpy_version, fmpy_version = np.__version__, fmpy.__version__
    proc = subprocess.run([str(python), "-m", "pip", "install", "--quiet", f"numpy=={numpy_version}",
                           f"fmpy=={fmpy_version}"], capture_output=True, text=True, timeout=900)
    assert proc.returncode == 0, proc.stderr[-3000:]
    return python


@pytest.fixture(scope="session")
def user_machine():
    """Skips where a user's machine cannot be simulated (see user_machine.py)."""
    from user_machine import can_unshare

    reason = can_unshare()
    if reason:
        pytest.skip(reason)


@pytest.fixture(scope="session")
def fmusim(tmp_path_factory):
    """fmusim compiled from the vendored sources (tests/fmus/fmusim), outside the checkout so a
    simulated user machine (which hides the checkout) can run it."""
    import fmusim_host

    try:
        return fmusim_host.build(tmp_path_factory.mktemp("fmusim"))
    except fmusim_host.MissingPackages as exc:
        pytest.skip(str(exc))
