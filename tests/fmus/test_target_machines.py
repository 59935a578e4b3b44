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
import glob
import os
from pathlib import Path
import shutil
import subprocess
import sys

import numpy as np
import pytest

from paths import REPO
from test_hosts import STEP, STEPS, extract, fmpy_values, plan

MINORS = (9, 10, 11, 12, 13)
# numpy per target Python, installed once (pip --target), outside the checkout (which is hidden)
NUMPY_CACHE = Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "neighbor-cosim" / "target-numpy"
PYENV_VERSIONS = Path(os.environ.get("PYENV_ROOT", Path.home() / ".pyenv")) / "versions"
DEBIAN_LIBPYTHON = "/usr/lib/x86_64-linux-gnu/libpython3.{minor}.so.1.0"


def _can_unshare():
    if os.geteuid() != 0 or shutil.which("unshare") is None:
        return "needs root and unshare (util-linux) for a private mount namespace"
    proc = subprocess.run(["unshare", "-m", "--propagation", "private", "true"], capture_output=True, text=True)
    return None if proc.returncode == 0 else f"mount namespaces not allowed here: {proc.stderr.strip()}"


pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="linux64 binaries, Linux mount namespaces")


def _hidden():
    """The folders a user's machine does not have: this checkout (with its virtual environment),
    the build's Python installation and its environment, when they are not the system's own."""
    folders = {REPO.resolve(), Path(sys.prefix).resolve(), Path(sys.base_prefix).resolve()}
    folders = {f for f in folders if str(f) not in ("/", "/usr", "/usr/local")}
    return sorted(str(f) for f in folders if not any(o in f.parents for o in folders))  # outermost


def _pyenv_python(minor):
    found = sorted(glob.glob(str(PYENV_VERSIONS / f"3.{minor}.*" / "bin" / f"python3.{minor}")))
    found = [p for p in found if Path(p).parents[1].joinpath("lib", f"libpython3.{minor}.so.1.0").is_file()]
    return found[-1] if found else None


def _targets():
    """(id, python executable, folder holding it (goes on PATH), how to install numpy for it)."""
    out = []
    for minor in MINORS:
        python = _pyenv_python(minor)
        if python:
            out.append((f"pyenv-3.{minor}", python, str(Path(python).parent), python))
        else:
            out.append((f"pyenv-3.{minor}", None, None, None))
    debian = "/usr/bin/python3.11"
    if os.path.isfile(debian) and os.path.isfile(DEBIAN_LIBPYTHON.format(minor=11)):
        # Debian has no pip by default: any CPython 3.11's pip installs the same cp311 wheel
        out.append(("debian-3.11", debian, "/usr/bin", _pyenv_python(11) or sys.executable))
    else:
        out.append(("debian-3.11", None, None, None))
    return out


TARGETS = _targets()


def _numpy_for(target_id, installer, minor):
    """A folder with numpy for CPython 3.minor (pip --target, cached under build/)."""
    folder = NUMPY_CACHE / f"3.{minor}"
    if (folder / "numpy" / "__init__.py").is_file():
        return folder
    probe = subprocess.run([installer, "-c", "import sys; print(sys.version_info[1])"], capture_output=True,
                           text=True)
    if probe.returncode != 0 or probe.stdout.strip() != str(minor):
        pytest.skip(f"{target_id}: no CPython 3.{minor} pip to install numpy for it")
    tmp = folder.with_name(folder.name + ".partial")
    shutil.rmtree(tmp, ignore_errors=True)
    proc = subprocess.run([installer, "-m", "pip", "install", "--quiet", "--disable-pip-version-check",
                           "--target", str(tmp), "numpy"], capture_output=True, text=True, timeout=900)
    if proc.returncode != 0:
        pytest.skip(f"{target_id}: numpy for CPython 3.{minor} did not install: {proc.stderr.strip()[-300:]}")
    tmp.rename(folder)
    return folder


def _on_user_machine(command, path_dirs, pythonpath=None, hide_all_python=False, also_hidden=()):
    """Run `command` in a private mount namespace where the build's Python and this checkout
    (and `also_hidden`) are empty folders; with hide_all_python, no CPython is left (pyenv
    hidden, the system's libpython and python3 replaced by empty files)."""
    mounts = [f"mount -t tmpfs none {folder}" for folder in [*_hidden(), *also_hidden]]
    if hide_all_python:
        mounts.append(f"mount -t tmpfs none {PYENV_VERSIONS.parent}")
        for pattern in ("/usr/lib/x86_64-linux-gnu/libpython3*.so*", "/usr/bin/python3*", "/usr/local/bin/python3*"):
            mounts += [f"mount --bind /dev/null {f}" for f in glob.glob(pattern)]
    env = ["env", "-i", "PATH=" + ":".join(path_dirs + ["/usr/bin", "/bin"]), "HOME=/tmp"]
    if pythonpath:
        env.append(f"PYTHONPATH={pythonpath}")
    script = " && ".join(mounts + ['exec "$@"'])
    return subprocess.run(["unshare", "-m", "--propagation", "private", "sh", "-c", script, "sh", *env, *command],
                          capture_output=True, text=True, timeout=600)


@pytest.fixture(scope="module")
def user_machine():
    reason = _can_unshare()
    if reason:
        pytest.skip(reason)


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


def _host_command(c_host, folder, model, guid, opts, rounds):
    return [str(c_host), str(folder), model, guid, *opts, "--steps", str(STEPS), "--step", str(STEP),
            "--rounds", str(rounds)]


@pytest.mark.parametrize("target", TARGETS, ids=[t[0] for t in TARGETS])
def test_every_fmu_runs_on_a_user_machine(target, user_machine, c_host, fmu_folders):
    """The user's CPython found on PATH, its home derived from where its library is, numpy from
    PYTHONPATH; values equal the build machine's to 1e-12."""
    target_id, python, bin_dir, installer = target
    if python is None:
        pytest.skip(f"{target_id}: not on this machine")
    prefix = Path(python).parents[1]
    if any(str(prefix) == h or Path(h) in prefix.parents for h in _hidden()):
        pytest.skip(f"{target_id}: the build's own Python ({prefix}), which a user's machine does not have")
    minor = int(target_id.rsplit(".", 1)[1])
    numpy_dir = _numpy_for(target_id, installer, minor)

    def run(item):
        name, (folder, model, guid, opts, expected) = item
        return name, expected, _on_user_machine(_host_command(c_host, folder, model, guid, opts, 1), [bin_dir],
                                                str(numpy_dir))

    with ThreadPoolExecutor(os.cpu_count() or 2) as pool:  # each host is a process of its own
        for name, expected, proc in pool.map(run, fmu_folders.items()):
            assert proc.returncode == 0 and "DONE failures=0" in proc.stdout, \
                f"{target_id} {name}:\n{proc.stdout[-3000:]}\n{proc.stderr[-2000:]}"
            started = next(line for line in proc.stdout.splitlines() if "in a Python this FMU started" in line)
            assert f"Python 3.{minor}." in started and f"({prefix})" in started, started
            got = [float(line.split()[2]) for line in proc.stdout.splitlines() if line.startswith("GET ")]
            np.testing.assert_allclose(got, expected, rtol=1e-12, atol=0, err_msg=f"{target_id} {name}")


def test_without_python_every_fmu_refuses_and_the_host_exits(user_machine, c_host, fmu_folders):
    """No CPython anywhere: fmi2Instantiate returns NULL with a message naming what was looked
    for and what to install; the host calls again (a second round) and exits by itself."""
    for name, (folder, model, guid, opts, _) in fmu_folders.items():
        proc = _on_user_machine(_host_command(c_host, folder, model, guid, opts, 2), [], hide_all_python=True)
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
    proc = _on_user_machine(_host_command(c_host, folder, model, guid, opts, 1), [],
                            also_hidden=[str(PYENV_VERSIONS.parent), "/usr/lib/python3.11"])
    assert proc.returncode == 3, f"exit {proc.returncode}\n{proc.stdout[-2000:]}\n{proc.stderr[-2000:]}"
    assert "no standard library beside it" in proc.stdout and libpython in proc.stdout, proc.stdout


def test_the_python_the_user_names_is_the_one_used(user_machine, c_host, fmu_folders):
    """NEIGHBOR_FMU_LIBPYTHON wins over the python3 on PATH; a wrong one is reported, not
    replaced by another Python."""
    folder, model, guid, opts, expected = fmu_folders["Gyro"]
    python = _pyenv_python(12)
    if python is None:
        pytest.skip("needs a CPython 3.12 with its shared library (pyenv)")
    numpy_dir = _numpy_for("pyenv-3.12", python, 12)
    lib = str(Path(python).parents[1] / "lib" / "libpython3.12.so.1.0")
    command = _host_command(c_host, folder, model, guid, opts, 1)
    proc = _on_user_machine(["env", f"NEIGHBOR_FMU_LIBPYTHON={lib}", *command], ["/usr/bin"], str(numpy_dir))
    assert proc.returncode == 0 and "Python 3.12." in proc.stdout, proc.stdout[-2000:]
    proc = _on_user_machine(["env", "NEIGHBOR_FMU_LIBPYTHON=/nowhere/libpython3.12.so", *command], ["/usr/bin"],
                            str(numpy_dir))
    assert proc.returncode == 3 and "/nowhere/libpython3.12.so (NEIGHBOR_FMU_LIBPYTHON): not found" in proc.stdout
