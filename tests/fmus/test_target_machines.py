"""The FMUs on a user's machine, not the build machine's: a C host (no Python in it) in a private
mount namespace that hides the build's Python installation and this checkout (its virtual
environment and sources), with one CPython 3.x of this machine on PATH and only numpy for it on
PYTHONPATH and no project variable set. Every FMU must load, run and unload with the values the
build machine computes; with no Python at all, every FMU must refuse fmi2Instantiate with a
message and the host must exit by itself.

Needs root and `unshare` (CI has both). CPython versions not on this machine are skipped with the
reason; so is the whole module where mount namespaces are not allowed.
"""
from concurrent.futures import ThreadPoolExecutor
import os
from pathlib import Path
import sys

import numpy as np
import pytest

from test_hosts import STEP, STEPS, extract, fmpy_values, plan
from user_machine import DEBIAN_LIBPYTHON, PYENV_VERSIONS, TARGETS, hidden, numpy_for, on_user_machine, pyenv_python

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="linux64 binaries, Linux mount namespaces")

@pytest.fixture(scope="module")
def fmu_folders(fmu_paths, tmp_path_factory):
    """Every FMU extracted outside the checkout, with what to call and the build machine's values."""
    root = tmp_path_factory.mktemp("user_fmus")
    out = {}
    for name, path in sorted(fmu_paths.items()):
        folder = extract(path, root / name)
        guid, model, opts, outputs = plan(path)
        expected = fmpy_values(path, folder, outputs, opts[:3] if opts[:1] == ["--set-real"] else [])
        out[name] = (folder, model, guid, opts, list(expected))
    return out


def _user_python(target):
    """(id, bin folder, prefix, minor version, numpy folder) of a target's CPython; the test is
    skipped where this machine does not have it or it is the build's own."""
    target_id, python, bin_dir, installer = target
    if python is None:
        pytest.skip(f"{target_id}: not on this machine")
    prefix = Path(python).parents[1]
    if any(str(prefix) == h or Path(h) in prefix.parents for h in hidden()):
        pytest.skip(f"{target_id}: the build's own Python ({prefix}), which a user's machine does not have")
    minor = int(target_id.rsplit(".", 1)[1])
    return target_id, bin_dir, prefix, minor, numpy_for(target_id, installer, minor)


def _host_command(c_host, folder, model, guid, opts, rounds):
    return [str(c_host), str(folder), model, guid, *opts, "--steps", str(STEPS), "--step", str(STEP),
            "--rounds", str(rounds)]


@pytest.mark.parametrize("target", TARGETS, ids=[t[0] for t in TARGETS])
def test_every_fmu_runs_on_a_user_machine(target, user_machine, c_host, fmu_folders):
    """The user's CPython found on PATH, its home derived from where its library is, numpy from
    PYTHONPATH; values equal the build machine's to 1e-12."""
    target_id, bin_dir, prefix, minor, numpy_dir = _user_python(target)

    def run(item):
        name, (folder, model, guid, opts, expected) = item
        return name, expected, on_user_machine(_host_command(c_host, folder, model, guid, opts, 1), [bin_dir],
                                                str(numpy_dir))

    with ThreadPoolExecutor(os.cpu_count() or 2) as pool:  # each host is a process of its own
        for name, expected, proc in pool.map(run, fmu_folders.items()):
            assert proc.returncode == 0 and "DONE failures=0" in proc.stdout, \
                f"{target_id} {name}:\n{proc.stdout[-3000:]}\n{proc.stderr[-2000:]}"
            started = next(line for line in proc.stdout.splitlines() if "in a Python this FMU started" in line)
            assert f"Python 3.{minor}." in started and f"({prefix})" in started, started
            got = [float(line.split()[2]) for line in proc.stdout.splitlines() if line.startswith("GET ")]
            np.testing.assert_allclose(got, expected, rtol=1e-12, atol=0, err_msg=f"{target_id} {name}")


FMI3_SAMPLE = ("RigidBody", "AttitudeEstimator", "MissionManager", "Power", "Gyro")


@pytest.mark.parametrize("target", TARGETS, ids=[t[0] for t in TARGETS])
def test_fmi3_fmus_in_fmusim_on_a_user_machine(target, user_machine, fmusim, fmu3_paths, tmp_path):
    """FMI 3.0 FMUs (the same runtime core, behind the FMI 3.0 entry points) in fmusim on the
    user's machine: the user's CPython found on PATH; results equal fmusim's on the build
    machine, value for value."""
    import shutil

    import fmusim_host

    target_id, bin_dir, _, _, numpy_dir = _user_python(target)
    for name in FMI3_SAMPLE:
        fmu = tmp_path / f"{name}.fmu"  # outside the checkout, which the user's machine does not have
        shutil.copy(fmu3_paths[name], fmu)
        assert fmusim_host.run(fmusim, fmu, tmp_path / f"{name}_build.csv", 0.045, 0.015).returncode == 0
        proc = on_user_machine(fmusim_host.command(fmusim, fmu, tmp_path / f"{name}_user.csv", 0.045, 0.015),
                               [bin_dir], str(numpy_dir))
        assert proc.returncode == 0, f"{target_id} {name}:\n{proc.stdout[-3000:]}\n{proc.stderr[-2000:]}"
        expected = fmusim_host.read(tmp_path / f"{name}_build.csv")
        got = fmusim_host.read(tmp_path / f"{name}_user.csv")
        assert got.keys() == expected.keys()
        for variable, values in expected.items():
            assert got[variable].tolist() == values.tolist(), f"{target_id} {name}.{variable}"


def test_without_python_every_fmu_refuses_and_the_host_exits(user_machine, c_host, fmu_folders):
    """No CPython anywhere: fmi2Instantiate returns NULL with a message naming what was looked
    for and what to install; the host calls again (a second round) and exits by itself."""
    for name, (folder, model, guid, opts, _) in fmu_folders.items():
        proc = on_user_machine(_host_command(c_host, folder, model, guid, opts, 2), [], hide_all_python=True)
        assert proc.returncode == 3, f"{name}: exit {proc.returncode}\n{proc.stdout[-2000:]}\n{proc.stderr[-2000:]}"
        assert proc.stdout.count("STATUS fmi2Instantiate NULL") == 2 and "DONE failures=2" in proc.stdout, name
        assert "found none it can use" in proc.stdout and "libpython3.13.so.1.0" in proc.stdout, proc.stdout
        assert "NEIGHBOR_FMU_LIBPYTHON" in proc.stdout, proc.stdout


def test_a_python_without_its_standard_library_is_refused_not_fatal(user_machine, c_host, fmu_folders):
    """The failure that used to exit the host (Python's init finding no `encodings`): a library
    whose standard library is gone is passed over with the reason, and the host lives on."""
    folder, model, guid, opts, _ = fmu_folders["Gyro"]
    libpython = DEBIAN_LIBPYTHON.format(minor=11)
    if not os.path.isfile(libpython) or not os.path.isdir("/usr/lib/python3.11"):
        pytest.skip("needs Debian's python3.11 and libpython3.11")
    # pyenv hidden too: the only CPython left is the one without its standard library
    proc = on_user_machine(_host_command(c_host, folder, model, guid, opts, 1), [],
                            also_hidden=[str(PYENV_VERSIONS.parent), "/usr/lib/python3.11"])
    assert proc.returncode == 3, f"exit {proc.returncode}\n{proc.stdout[-2000:]}\n{proc.stderr[-2000:]}"
    assert "no standard library beside it" in proc.stdout and libpython in proc.stdout, proc.stdout


def test_the_python_the_user_names_is_the_one_used(user_machine, c_host, fmu_folders):
    """NEIGHBOR_FMU_LIBPYTHON wins over the python3 on PATH; a wrong one is reported, not
    replaced by another Python."""
    folder, model, guid, opts, expected = fmu_folders["Gyro"]
    python = pyenv_python(12)
    if python is None:
        pytest.skip("needs a CPython 3.12 with its shared library (pyenv)")
    numpy_dir = numpy_for("pyenv-3.12", python, 12)
    lib = str(Path(python).parents[1] / "lib" / "libpython3.12.so.1.0")
    command = _host_command(c_host, folder, model, guid, opts, 1)
    proc = on_user_machine(["env", f"NEIGHBOR_FMU_LIBPYTHON={lib}", *command], ["/usr/bin"], str(numpy_dir))
    assert proc.returncode == 0 and "Python 3.12." in proc.stdout, proc.stdout[-2000:]
    proc = on_user_machine(["env", "NEIGHBOR_FMU_LIBPYTHON=/nowhere/libpython3.12.so", *command], ["/usr/bin"],
                            str(numpy_dir))
    assert proc.returncode == 3 and "/nowhere/libpython3.12.so (NEIGHBOR_FMU_LIBPYTHON): not found" in proc.stdout
