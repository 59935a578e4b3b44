"""The attitude models' native steps (components.core.native): their FMUs' steps as cfuncs that
the FMU runtime calls without Python, over the same kernels as the Python steps (the same bits).
Imported once numba is in the process; `step(name)` compiles only the step asked for (seconds, the
first time on a machine) or loads it from numba's cache (milliseconds once numba runs)."""
import math

from ..core import jit, native
from . import deorbit_tracking, detumble, mass_properties, rigid_body as body, thrusters


def rigid_body(context, t, h):
    """RigidBody's FMU step (RigidBody.step_and_publish, NeighborSlave.mark_published): context =
    the state x, the shared values, the input and output indices, the share flags and
    (max_substep, 1 for euler). 0: stepped, the outputs published or, when the quaternion cannot
    be published, left stale for the get to raise; 1: an input is not finite, nothing changed."""
    return _rigid_body_step(context, h)


def rigid_body_following(context, t, h):
    """RigidBody's FMU step with propellant_mass_properties, while the propellant drawn stays
    within mass_properties.RESOLUTION of the amount its inertia follows (RigidBody.follow_propellant
    has nothing to do then): context = rigid_body's, then the followed amount's cell
    (RigidBody.drawn_cell) and the indices of the inputs propellant_used and rcs_propellant.
    1 also when the inertia must follow: nothing changed, and the Python step recomputes it."""
    pairs = native.entries(context, 8)
    values, cell, used = native.float64s(pairs, 1), native.float64s(pairs, 6), native.int64s(pairs, 7)
    drawn = values[used[0]] + values[used[1]]  # the Python step's sum of the two inputs
    if not abs(drawn - cell[0]) < mass_properties.RESOLUTION:
        return 1
    return _rigid_body_step(context, h)


@jit.numba.njit(inline="always")
def _rigid_body_step(context, h):
    pairs = native.entries(context, 6)
    x, values = native.float64s(pairs, 0), native.float64s(pairs, 1)
    inputs, outputs = native.int64s(pairs, 2), native.int64s(pairs, 3)
    flags, settings = native.int32s(pairs, 4), native.float64s(pairs, 5)
    euler = settings[1] != 0.0
    substeps = 1 if euler else max(1, math.ceil(h / settings[0] - 1e-9))  # RigidBody._substeps
    error = body.step_publish_into(x, values, inputs, outputs, h, substeps, euler)
    if error > 0:
        return 1
    fresh = 1 if error == 0 else 0
    flags[0] = fresh
    flags[1] = fresh
    return 0


def thruster_pairs(context, t, h):
    """RcsThrusters' FMU step (ThrusterPairs.step_into, mark_published): context = the pairs'
    state, the shared values, the input and output indices, the share flags. 1: a command is not
    finite, nothing changed."""
    return _thruster_pairs(context, h, True)


def thruster_pairs_publish(context, t, h):
    """RcsThrusters' publish (ThrusterPairs.step_into without stepping, mark_published) on
    thruster_pairs' context; t and h unused. 1: a command is not finite, nothing changed."""
    return _thruster_pairs(context, 0.0, False)


@jit.numba.njit(inline="always")
def _thruster_pairs(context, h, stepping):
    pairs = native.entries(context, 5)
    state, values = native.float64s(pairs, 0), native.float64s(pairs, 1)
    inputs, outputs, flags = native.int64s(pairs, 2), native.int64s(pairs, 3), native.int32s(pairs, 4)
    if thrusters.pairs_into(state, values, inputs, outputs, h, stepping):
        return 1
    flags[0] = 1
    flags[1] = 1
    return 0


def detumble_law(context, t, h):
    """DetumbleController's FMU step (DetumbleController.step_into, mark_published): context = the
    law's constants, the shared values, the input and output indices, the share flags and the
    settle timer's cell (time_inside)."""
    return _detumble_law(context, h, True)


def detumble_law_publish(context, t, h):
    """DetumbleController's publish (DetumbleController.step_into without stepping,
    mark_published) on detumble_law's context; t and h unused."""
    return _detumble_law(context, 0.0, False)


@jit.numba.njit(inline="always")
def _detumble_law(context, h, stepping):
    pairs = native.entries(context, 6)
    constants, values = native.float64s(pairs, 0), native.float64s(pairs, 1)
    inputs, outputs, flags = native.int64s(pairs, 2), native.int64s(pairs, 3), native.int32s(pairs, 4)
    cell = native.float64s(pairs, 5)
    cell[0] = detumble.detumble_into(constants, values, inputs, outputs, h, cell[0], stepping)
    flags[0] = 1
    flags[1] = 1
    return 0


def tracking_law(context, t, h):
    """TrackingController's FMU step (tracking_into stepping: follow the target, advance q_d; the
    outputs left stale): context = the law's constants and state, the shared values, the input and
    output indices, the share flags and (target_from_input). 1: a target it refuses, nothing
    changed (the Python step raises the error)."""
    return _tracking_law(context, h, True)


def tracking_law_publish(context, t, h):
    """TrackingController's publish (tracking_into without stepping, mark_published) on
    tracking_law's context; t and h unused. 1: an input it refuses, for the Python publish."""
    return _tracking_law(context, 0.0, False)


@jit.numba.njit(inline="always")
def _tracking_law(context, h, stepping):
    pairs = native.entries(context, 7)
    constants, x, values = native.float64s(pairs, 0), native.float64s(pairs, 1), native.float64s(pairs, 2)
    inputs, outputs, flags = native.int64s(pairs, 3), native.int64s(pairs, 4), native.int32s(pairs, 5)
    follow = native.float64s(pairs, 6)[0] != 0.0
    if deorbit_tracking.tracking_into(constants, x, values, inputs, outputs, h, stepping, follow):
        return 1
    fresh = 0 if stepping else 1
    flags[0] = fresh
    flags[1] = fresh
    return 0


# step(name): the cfunc of the step or publish `name` (rigid_body, rigid_body_following,
# thruster_pairs, thruster_pairs_publish, detumble_law, detumble_law_publish, tracking_law,
# tracking_law_publish)
step = native.compiler(globals())
