"""numba's `njit` when numba is installed, the plain Python function when it is not.

The kernels (gravity, atmospheres, space-weather lookups, the Cowell and orbit-averaged
integrators) are written in the subset of Python that numba compiles, so the same source runs
either way with the same results; numba only makes it faster. Setting the environment variable
NEIGHBOR_COSIM_NUMBA=0 before the first import runs the plain-Python path even where numba is
installed (the tests compare the two).

`objmode` lets compiled code call back into Python (the NRLMSIS density through pymsis); in the
plain-Python path it is a no-op context."""
import contextlib
import os

try:
    import numba
except ImportError:  # numba is optional: plain Python then
    numba = None

ENABLED = numba is not None and os.environ.get("NEIGHBOR_COSIM_NUMBA", "1") != "0"


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
