"""A user's machine, simulated on this one: a private mount namespace (`unshare -m`, as root) in
which this checkout, its virtual environment and the build's Python installation are empty
folders, with one CPython of this machine on PATH and numpy for it (installed once with pip
--target, outside the checkout) on PYTHONPATH, and no project variable set."""
import glob
import os
from pathlib import Path
import shutil
import subprocess
import sys
import tempfile

import pytest

from paths import REPO

MINORS = (9, 10, 11, 12, 13)
# numpy per target Python, installed once (pip --target), outside the checkout (which is hidden)
NUMPY_CACHE = Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "neighbor-cosim" / "target-numpy"
PYENV_VERSIONS = Path(os.environ.get("PYENV_ROOT", Path.home() / ".pyenv")) / "versions"
DEBIAN_LIBPYTHON = "/usr/lib/x86_64-linux-gnu/libpython3.{minor}.so.1.0"


def can_unshare():
    if os.geteuid() != 0 or shutil.which("unshare") is None:
        return "needs root and unshare (util-linux) for a private mount namespace"
    proc = subprocess.run(["unshare", "-m", "--propagation", "private", "true"], capture_output=True, text=True)
    if proc.returncode != 0:
        return f"mount namespaces not allowed here: {proc.stderr.strip()}"
    return _mounts_leak()


def _mounts_leak():
    """Whether a tmpfs mounted in a private namespace shows in this one (a sandbox whose mount
    namespaces do not isolate): then hiding the checkout would hide it from every test, as it
    did on one CI machine (the rest of the suite failed with its working directory gone)."""
    probe = Path(tempfile.mkdtemp(prefix="neighbor-unshare-probe-"))
    (probe / "marker").write_text("seen from this namespace\n")
    try:
        subprocess.run(["unshare", "-m", "--propagation", "private", "sh", "-c",
                        f"mount --make-rprivate / && mount -t tmpfs none {probe}"], capture_output=True, timeout=60)
        if os.path.ismount(probe) or not (probe / "marker").is_file():
            subprocess.run(["umount", "-l", str(probe)], capture_output=True)
            return "mounts made in a private mount namespace show outside it here (no isolation)"
        return None
    finally:
        shutil.rmtree(probe, ignore_errors=True)


def hidden():
    """The folders a user's machine does not have: this checkout (with its virtual environment),
    the build's Python installation and its environment, when they are not the system's own."""
    folders = {REPO.resolve(), Path(sys.prefix).resolve(), Path(sys.base_prefix).resolve()}
    folders = {f for f in folders if str(f) not in ("/", "/usr", "/usr/local")}
    return sorted(str(f) for f in folders if not any(o in f.parents for o in folders))  # outermost


def pyenv_python(minor):
    found = sorted(glob.glob(str(PYENV_VERSIONS / f"3.{minor}.*" / "bin" / f"python3.{minor}")))
    found = [p for p in found if Path(p).parents[1].joinpath("lib", f"libpython3.{minor}.so.1.0").is_file()]
    return found[-1] if found else None


def targets():
    """(id, python executable, folder holding it (goes on PATH), how to install numpy for it)."""
    out = []
    for minor in MINORS:
        python = pyenv_python(minor)
        if python:
            out.append((f"pyenv-3.{minor}", python, str(Path(python).parent), python))
        else:
            out.append((f"pyenv-3.{minor}", None, None, None))
    debian = "/usr/bin/python3.11"
    if os.path.isfile(debian) and os.path.isfile(DEBIAN_LIBPYTHON.format(minor=11)):
        # Debian has no pip by default: any CPython 3.11's pip installs the same cp311 wheel
        out.append(("debian-3.11", debian, "/usr/bin", pyenv_python(11) or sys.executable))
    else:
        out.append(("debian-3.11", None, None, None))
    return out


TARGETS = targets()


def numpy_for(target_id, installer, minor):
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


def on_user_machine(command, path_dirs, pythonpath=None, hide_all_python=False, also_hidden=()):
    """Run `command` in a private mount namespace where the build's Python and this checkout
    (and `also_hidden`) are empty folders; with hide_all_python, no CPython is left (pyenv
    hidden, the system's libpython and python3 replaced by empty files)."""
    mounts = [f"mount -t tmpfs none {folder}" for folder in [*hidden(), *also_hidden]]
    if hide_all_python:
        mounts.append(f"mount -t tmpfs none {PYENV_VERSIONS.parent}")
        for pattern in ("/usr/lib/x86_64-linux-gnu/libpython3*.so*", "/usr/bin/python3*", "/usr/local/bin/python3*"):
            mounts += [f"mount --bind /dev/null {f}" for f in glob.glob(pattern)]
    env = ["env", "-i", "PATH=" + ":".join(path_dirs + ["/usr/bin", "/bin"]), "HOME=/tmp"]
    if pythonpath:
        env.append(f"PYTHONPATH={pythonpath}")
    # private again from inside (a failure stops the script before any mount)
    script = " && ".join(["mount --make-rprivate /", *mounts, 'exec "$@"'])
    folders = [*hidden(), *also_hidden] + ([str(PYENV_VERSIONS.parent)] if hide_all_python else [])
    covered = [f for f in folders if not os.path.ismount(f)]
    try:
        return subprocess.run(["unshare", "-m", "--propagation", "private", "sh", "-c", script, "sh", *env,
                               *command], capture_output=True, text=True, timeout=600)
    finally:
        leaked = [f for f in covered if os.path.ismount(f)]
        for folder in leaked:  # the checkout must not stay hidden from the rest of the session
            subprocess.run(["umount", "-l", folder], capture_output=True)
        if leaked:
            raise RuntimeError(f"the user machine's mounts leaked out of their namespace over {leaked} "
                               "(unmounted again)")
