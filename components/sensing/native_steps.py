"""The gyro's native steps (components.core.native): its FMU's step and publish as cfuncs that the
FMU runtime calls without Python, over the same kernel as the Python step (the same bits).
Imported once numba is in the process (see components.attitude.native_steps)."""
from ..core import jit, native
from . import sensors


def gyro(context, t, h):
    """Gyro's FMU step (sensors.gyro_into stepping, then publish_after_step): context = the gyro's
    constants, state and noise block, the shared values, the input and output indices, the share
    flags. 1: the block is used up, nothing changed (the Python step draws the next); a rate that
    is not finite leaves the output stale (the get raises the error, as after the Python step)."""
    return _gyro(context, h, True)


def gyro_publish(context, t, h):
    """Gyro's publish (gyro_into without stepping, mark_published) on gyro's context; t and h
    unused. 1: a rate that is not finite, for the Python publish to raise."""
    return _gyro(context, 0.0, False)


@jit.numba.njit(inline="always")
def _gyro(context, h, stepping):
    pairs = native.entries(context, 7)
    constants, x, block = native.float64s(pairs, 0), native.float64s(pairs, 1), native.float64s(pairs, 2)
    values, inputs, outputs = native.float64s(pairs, 3), native.int64s(pairs, 4), native.int64s(pairs, 5)
    flags = native.int32s(pairs, 6)
    status = sensors.gyro_into(constants, x, block, values, inputs, outputs, h, stepping)
    if status == 1 or (status == 2 and not stepping):
        return 1
    fresh = 1 if status == 0 else 0
    flags[0] = fresh
    flags[1] = fresh
    return 0


step = native.compiler(globals())  # step("gyro"), step("gyro_publish")
