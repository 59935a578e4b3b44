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
one FMU build compile once per machine; an entry is stamped with the package's name (the digest
of all its code), as the source file may be gone when a kernel is first called.

Outside an FMU (a checkout, an installed wheel), numba would check only the source file of the
cached function itself, while a kernel's compiled code holds the code of the kernels it calls
from other files (the orbit's integration holds the atmosphere's): an edited atmosphere left the
orbit on its old code. `ComponentsCacheLocator` keeps numba's cache beside the sources but stamps
every entry with a digest of the whole components package, so any edit of it compiles them
again.

numba is imported when the first kernel is called, not when a module declares one: importing it
and initializing its compiler costs about 0.9 s, more than a short run's whole work. A kernel
declared `plain_first` (one whose plain-Python run gives numba's bits exactly, which
tests/components/orbit/test_without_numba.py checks) runs as plain Python while numba is not yet
in the process, for up to PLAIN_CALLS calls of such kernels per copy of this module (every FMU has
its own); then numba is loaded and the kernels run compiled. So a short run of the attitude models
(`neighbor-cosim run detumble`, an FMU's first steps in a C host) never pays for numba, and a long
one pays once. NEIGHBOR_COSIM_NUMBA=1 compiles every kernel at its first call (no plain start)."""
import contextlib
import functools
import hashlib
import importlib.util
import os
import re
import sys

_CHOICE = os.environ.get("NEIGHBOR_COSIM_NUMBA", "")  # "0": never numba; "1": numba from the first call
_INSTALLED = importlib.util.find_spec("numba") is not None
ENABLED = _CHOICE != "0" and _INSTALLED
numba = None  # the module, once a kernel needed it (_numba)
# The plain-Python calls the plain-first kernels of this copy may take before numba is loaded: about
# half a second of the attitude models' steps here (30 calls and 144 us a step of the rigid body's RK4,
# the thruster pairs and the detumble law), against 0.9 s for numba's start.
PLAIN_CALLS = 0 if _CHOICE == "1" else 100_000
_plain_calls_left = PLAIN_CALLS

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
            self._package, inside = fmu_package_of(py_file)
            root = AppDirs(appname="numba", appauthor=False).user_cache_dir
            self._cache_path = os.path.join(root, "neighbor-cosim-fmus", self._package, inside)

        def get_source_stamp(self):
            # the package's name carries the digest of all its code (the kernels it calls in other
            # files too); its source file may be gone: a kernel is compiled at its first call, and
            # instances of one FMU build share the modules of the first extraction
            return self._package

        @classmethod
        def from_function(cls, py_func, py_file):
            if fmu_package_of(py_file) is None:
                return None
            self = cls(py_func, py_file)
            try:
                self.ensure_cache_path()
            except OSError:  # numba's own locators then (as numba does for its own)
                return None
            return self

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


def _numba():
    """numba, imported (with our cache locators, and kernels accepted where numba code names or
    takes one) at the first kernel that needs it."""
    global numba
    if numba is None:
        import numba as module
        from numba.extending import typeof_impl

        _install_fmu_cache_locator()
        # numba code that calls a Kernel (a global, a closure's variable, an argument) calls its dispatcher
        typeof_impl.register(Kernel)(lambda kernel, context: typeof_impl(kernel.dispatcher, context))
        numba = module
    return numba


class Kernel:
    """A function numba compiles (or loads from its cache) when it is first called. Calls by the
    module's own name go straight to numba's dispatcher from then on: the name is rebound to it."""

    def __init__(self, function, options, plain_first, plain=None):
        functools.update_wrapper(self, function)
        self.py_func = function
        self._plain = function if plain is None else plain
        self._options = options
        self._plain_first = plain_first
        self._dispatcher = None

    def __call__(self, *args):
        global _plain_calls_left
        if self._dispatcher is None:
            if self._plain_first and _plain_calls_left > 0 and "numba" not in sys.modules:
                _plain_calls_left -= 1
                return self._plain(*args)
            self.dispatcher  # noqa: B018 - loads numba and the kernel
        return self._dispatcher(*args)

    @property
    def dispatcher(self):
        """numba's dispatcher of the function (numba imported and the module's name rebound)."""
        if self._dispatcher is None:
            self._dispatcher = _numba().njit(**self._options)(self.py_func)
            names = self.py_func.__globals__
            for name in [n for n, value in names.items() if value is self]:
                names[name] = self._dispatcher
        return self._dispatcher

    def __getattr__(self, name):  # what else numba's dispatcher has (its cache, its signatures)
        if name.startswith("__"):
            raise AttributeError(name)
        return getattr(self.dispatcher, name)

    def __reduce__(self):  # pickled as numba pickles its dispatchers (by value), as before it was lazy
        return self.dispatcher.__reduce__()


def function_of(kernel):
    """The Python function behind `kernel` (a Kernel, numba's dispatcher or the function itself):
    one key for a kernel whether numba has loaded it yet or not (a module's name for it is rebound
    to numba's dispatcher when it is)."""
    return getattr(kernel, "py_func", kernel)


def loaded(kernel):
    """numba's dispatcher of a Kernel (numba loaded now), else `kernel` itself: for a kernel held in a
    table and called at every step, whose call through the Kernel costs about 0.5 us more."""
    return kernel.dispatcher if isinstance(kernel, Kernel) else kernel


def njit(*args, plain_first=False, plain=None, **kwargs):
    """A decorator making a Kernel with numba.njit's options (numba then compiles at the first
    call), or returning the function unchanged where numba is not used. `plain_first`: the plain
    Python run of the function, and of every kernel it calls, gives numba's bits (tested).
    `plain`: the function that plain Python calls instead (the library function that the compiled
    one reproduces, such as math.hypot)."""
    if len(args) == 1 and callable(args[0]) and not kwargs and plain is None:
        return njit(plain_first=plain_first)(args[0])
    if not ENABLED:
        return lambda function: function if plain is None else plain
    return lambda function: Kernel(function, dict(kwargs), plain_first, plain)


def _plain_objmode(**types):
    return contextlib.nullcontext()


def __getattr__(name):
    # numba recognizes its own objmode by identity when it compiles a `with` block: a module that
    # imports objmode imports numba
    if name == "objmode":
        return _numba().objmode if ENABLED else _plain_objmode
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def describe():
    """Which path the kernels take, for an FMU's log."""
    if ENABLED:
        from importlib.metadata import version
        return f"numba {version('numba')}: compiled kernels"
    why = "numba is not installed" if not _INSTALLED else "NEIGHBOR_COSIM_NUMBA=0"
    return f"{why}: plain-Python kernels (the same results, slower)"
