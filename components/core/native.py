"""Steps that the FMU runtime calls without Python: numba cfuncs over a model's own arrays.

A model's FMU step in Python costs a few microseconds of the interpreter around a kernel that
takes less than one: entering Python from the binary, the wrapper's method, numba's dispatch of
the kernel's arguments. A native step is a numba cfunc `int step(context, t, h)` that the binary
(fmus/runtime/neighbor_core.c) calls directly: `context` is the address of an int64 array of
(address, length) pairs, one per array the step reads or writes (`context()` builds it), and the
step calls the same kernels as the Python step on those arrays, so it gives the same bits. It
returns 0 when it took the step, anything else when it changed nothing (the Python step then takes
it, or raises the error the kernel's code stands for).

Imported once numba is in the process (NeighborSlave.native_ready, arm_native): it needs numba itself.
"""
import numpy as np
import numba
from numba import carray, types
from numba.core.extending import intrinsic

from . import jit

jit._numba()  # our cache locators and the Kernels' typing, as for any kernel

STEP = types.int32(types.int64, types.float64, types.float64)  # step(context, t, h)


def _pointer_to(dtype):
    @intrinsic
    def at(typingctx, address):
        signature = types.CPointer(dtype)(types.int64)

        def codegen(context, builder, sig, args):
            return builder.inttoptr(args[0], context.get_value_type(types.CPointer(dtype)))

        return signature, codegen

    return at


float64_at, int64_at, int32_at = _pointer_to(types.float64), _pointer_to(types.int64), _pointer_to(types.int32)


@jit.numba.njit(inline="always")
def entries(context, n):
    """The context's `n` (address, length) pairs, as an int64 array of 2 n."""
    return carray(int64_at(context), (2 * n,))


@jit.numba.njit(inline="always")
def float64s(pairs, i):
    return carray(float64_at(pairs[2 * i]), (pairs[2 * i + 1],))


@jit.numba.njit(inline="always")
def int64s(pairs, i):
    return carray(int64_at(pairs[2 * i]), (pairs[2 * i + 1],))


@jit.numba.njit(inline="always")
def int32s(pairs, i):
    return carray(int32_at(pairs[2 * i]), (pairs[2 * i + 1],))


def context(*arrays):
    """The (address, length) pairs of `arrays` (C-contiguous; float64, int64 or int32 as the step
    reads them), as the int64 array whose address a step takes. The caller keeps the arrays."""
    for a in arrays:
        if not a.flags.c_contiguous:
            raise ValueError("a native step's arrays must be C-contiguous")
    return np.array([v for a in arrays for v in (a.ctypes.data, a.size)], dtype=np.int64)


def compiler(namespace):
    """`step(name)` for a module of native steps (its globals(), `namespace`): the cfunc of its
    function `name`, compiled at the first request (or loaded from numba's cache) and kept."""
    compiled = {}

    def step(name):
        if name not in compiled:
            compiled[name] = numba.cfunc(STEP, cache=True)(namespace[name])
        return compiled[name]

    return step
