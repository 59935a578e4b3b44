"""Fixtures of the FMU tests: the C host with no Python in it."""
from pathlib import Path
import subprocess

import fmpy
import pytest

from paths import TESTS

HOST_SOURCE = TESTS / "fmus" / "c_host" / "fmu_host.c"


@pytest.fixture(scope="session")
def c_host(tmp_path_factory):
    out = tmp_path_factory.mktemp("c_host") / "fmu_host"
    headers = Path(fmpy.__file__).parent / "c-code"
    cmd = ["gcc", "-std=c99", "-O1", "-Wall", "-Werror", f"-I{headers}", str(HOST_SOURCE), "-o", str(out),
           "-ldl", "-lpthread"]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    libs = subprocess.run(["ldd", str(out)], capture_output=True, text=True).stdout
    assert "python" not in libs  # the host itself has no Python
    return out
