"""numba's `njit` when numba is installed, the plain Python function when it is not.

The kernels (gravity, atmospheres, space-weather lookups, the Cowell and orbit-averaged
integrators) are written in the subset of Python that numba compiles, so the same source runs
either way with the same results; numba only makes it faster. Setting the environment variable
NEIGHBOR_COSIM_NUMBA=0 before the first import runs the plain-Python path even where numba is
installed (the tests compare the two).

`objmode` lets compiled code call back into Python (the NRLMSIS density through pymsis); in the
plain-Python path it is a no-op context.

Inside an FMU the kernels' sources are extracted to a new temporary folder for every run, where
numba's cache (beside the source) would be lost with the folder: each run would compile them
again (seconds for the orbit's and the estimator's). `FmuPackageCacheLocator` keeps the compiled
code of sources in one of our FMUs' private packages (resources/nc_<name>_<digest>/, the digest
is of the package's code) in the user's cache folder under that package's name, so the runs of
one FMU build compile once per machine; numba still checks each source's content hash.

Outside an FMU (a checkout, an installed wheel), numba would check only the source file of the
cached function itself, while a kernel's compiled code holds the code of the kernels it calls
from other files (the orbit's integration holds the atmosphere's): an edited atmosphere left the
orbit on its old code. `ComponentsCacheLocator` keeps numba's cache beside the sources but stamps
every entry with a digest of the whole components package, so any edit of it compiles them
again."""
import contextlib
import functools
import hashlib
import os
import re

try:
    import numba
except ImportError:  # numba is optional: plain Python then
    numba = None

ENABLED = numba is not None and os.environ.get("NEIGHBOR_COSIM_NUMBA", "1") != "0"

# an FMU's private package folder: builder.build_fmu names it <prefix>_<class>_<code digest>
_FMU_PACKAGE = re.compile(r"nc3?_[a-z0-9]+_[0-9a-f]{12}")


def components_root_of(py_file):
    """The folder of the components package (this one's, or a copy's) that py_file lies in, or None."""
    folder = os.path.dirname(os.path.abspath(py_file))
    while os.path.dirname(folder) != folder:
        if os.path.basename(folder) == "components" and os.path.isfile(os.path.join(folder, "core", "jit.py")):
            return folder
        folder = os.path.dirname(folder)
    return None


@functools.lru_cache(maxsize=None)
def components_digest(root):
    """sha256 of the names and contents of every .py file of the package at root (once per
    process: the sources do not change under a run)."""
    digest = hashlib.sha256()
    for folder, dirs, files in sorted(os.walk(root)):
        dirs[:] = sorted(d for d in dirs if d != "__pycache__")
        for name in sorted(f for f in files if f.endswith(".py")):
            path = os.path.join(folder, name)
            digest.update(os.path.relpath(path, root).encode() + b"\0")
            with open(path, "rb") as f:
                digest.update(f.read())
    return digest.hexdigest()


def fmu_package_of(py_file):
    """(package folder name, folder of py_file inside it) when py_file lies in one of our FMUs'
    private packages (.../resources/nc_<name>_<digest>/...), else None."""
    parts = os.path.abspath(py_file).split(os.sep)
    for i in range(len(parts) - 2, 0, -1):
        if parts[i - 1] == "resources" and _FMU_PACKAGE.fullmatch(parts[i]):
            return parts[i], os.path.join(*parts[i + 1:-1]) if i + 1 < len(parts) - 1 else ""
    return None


def _install_fmu_cache_locator():
    """Put FmuPackageCacheLocator first among numba's cache locators, ComponentsCacheLocator
    second (once per process: every FMU's copy of this module checks by name). They claim only
    files of our FMUs' packages and of the components package; a numba without the locator list
    keeps its own behaviour."""
    try:
        from numba.core import caching
        from numba.misc.appdirs import AppDirs
        # public names in recent numba, underscored in older ones (the pin allows 0.59)
        impl = getattr(caching, "CacheImpl", None) or caching._CacheImpl
        user_wide = getattr(caching, "UserWideCacheLocator", None) or caching._UserWideCacheLocator
        locators = impl._locator_classes
    except (ImportError, AttributeError):  # another numba's internals: its own caching then
        return
    if any(c.__name__ == "FmuPackageCacheLocator" for c in locators):
        return
    in_tree = getattr(caching, "InTreeCacheLocator", None) or caching._InTreeCacheLocator

    class FmuPackageCacheLocator(user_wide):
        def __init__(self, py_func, py_file):
            super().__init__(py_func, py_file)
            package, inside = fmu_package_of(py_file)
            root = AppDirs(appname="numba", appauthor=False).user_cache_dir
            self._cache_path = os.path.join(root, "neighbor-cosim-fmus", package, inside)

        @classmethod
        def from_function(cls, py_func, py_file):
            if fmu_package_of(py_file) is None:
                return None
            return super().from_function(py_func, py_file)

    class ComponentsCacheLocator(in_tree):
        def get_source_stamp(self):
            return components_digest(components_root_of(self._py_file))

        @classmethod
        def from_function(cls, py_func, py_file):
            if components_root_of(py_file) is None or fmu_package_of(py_file) is not None:
                return None
            return super().from_function(py_func, py_file)

    locators.insert(0, ComponentsCacheLocator)
    locators.insert(0, FmuPackageCacheLocator)


if ENABLED:
    _install_fmu_cache_locator()


def njit(*args, **kwargs):
    """numba.njit(*args, **kwargs), or a decorator that returns the function unchanged."""
    if ENABLED:
        return numba.njit(*args, **kwargs)
    if len(args) == 1 and callable(args[0]) and not kwargs:
        return args[0]
    return lambda function: function


def _plain_objmode(**types):
    return contextlib.nullcontext()


# numba recognizes its own objmode by identity when it compiles a `with` block
objmode = numba.objmode if ENABLED else _plain_objmode


def describe():
    """Which path the kernels take, for an FMU's log."""
    if ENABLED:
        return f"numba {numba.__version__}: compiled kernels"
    why = "numba is not installed" if numba is None else "NEIGHBOR_COSIM_NUMBA=0"
    return f"{why}: plain-Python kernels (the same results, slower)"
