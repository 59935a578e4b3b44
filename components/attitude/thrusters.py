"""RCS thruster pairs: applied torque, firing time and propellant (thesis Eq. 13-16, 74).

The commanded torque is rounded per axis to the nearest available level {-L, 0, +L}
(L from the geometry, Eq. 16), so a controller's already-quantized command passes through
unchanged and any other command maps to what the hardware can do. While a pair fires its
firing time accumulates; propellant follows Eq. 74 with the impulse of two thrusters:

    m_p = 2 F t_fire / (Isp g0)        (Appendix D/E `mpDetumble`, `mpSlew`)

where t_fire is summed over the three axes (the scripts add dt once per firing axis).
"""
import math

import numpy as np

from ..core.jit import njit
from ..mission.neighbor import SPACECRAFT
from . import thruster_control as tc

# ThrusterPairs.state: the firing times, the pair torques, the force, Isp and g0 (pairs_into's)
FIRE, LEVELS, FORCE, ISP, G0 = 0, 3, 6, 7, 8
# pairs_into's outputs, in the order of its `outputs` indices
PUBLISHED = (("torque_B", 3), ("thrust_flag", 3), ("torque_level", 3), ("fire_time", 3), ("fire_time_total", 1),
             ("propellant_mass", 1))


class ThrusterPairs:
    def __init__(self, force=tc.F_THRUSTER, a=SPACECRAFT.edge_a, c=SPACECRAFT.edge_c, isp=SPACECRAFT.isp,
                 g0=SPACECRAFT.g0):
        self.levels = tc.pair_torques(force, a, c)
        for name, value in (("Isp", isp), ("g0", g0)):
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"{name} = {value!r} must be a finite positive number")
        self.force, self.isp, self.g0 = float(force), float(isp), float(g0)
        self.state = np.array([0.0, 0.0, 0.0, *self.levels, self.force, self.isp, self.g0])

    @property
    def fire_time(self):
        """Accumulated firing time of the x, y, z pairs (s), as a list."""
        return self.state[FIRE:FIRE + 3].tolist()

    def flags(self, command):
        """-1/0/+1 per axis: nearest available level to the commanded torque."""
        return tc.nearest_pair_flags(command, self.levels)

    def applied_torque(self, command):
        return [f * lvl for f, lvl in zip(self.flags(command), self.levels)]

    def step(self, command, h):
        for i, f in enumerate(self.flags(command)):
            if f:
                self.state[FIRE + i] = self.state[FIRE + i] + h

    def step_into(self, values, inputs, outputs, h, stepping=True):
        """The FMU's step (stepping) or publish in one compiled call: the command at
        values[inputs[0:3]]; the outputs (PUBLISHED) written to values[outputs]."""
        error = pairs_into(self.state, values, inputs, outputs, h, stepping)
        if error:
            c = float(values[inputs[error - 1]])
            raise ValueError(f"torque_cmd_B[{error}] = {c!r} must be finite")

    def total_fire_time(self):
        return sum(self.fire_time)

    def propellant_mass(self):
        return 2.0 * self.force * self.total_fire_time() / (self.isp * self.g0)

    def get_state(self):
        return {"fire_time": list(self.fire_time)}

    def set_state(self, state):
        self.state[FIRE:FIRE + 3] = [float(x) for x in state["fire_time"]]


@njit(cache=True, plain_first=True)
def pairs_into(state, values, inputs, outputs, h, stepping):
    """ThrusterPairs on its state array: the flags nearest the command at values[inputs[0:3]]
    (thruster_control.nearest_pair_flags), with `stepping` the firing pairs' times advanced by h
    (step), then values[outputs] = the applied torque, the flags, the pair torques, the firing
    times, their sum and the propellant (the getters' values, PUBLISHED). The same operations as
    the Python methods. Returns 0, or 1 + the axis whose command is not finite (nothing changed)."""
    for i in range(3):
        if not math.isfinite(values[inputs[i]]):
            return i + 1
    for i in range(3):
        c, level = values[inputs[i]], state[LEVELS + i]
        half = 0.5 * level
        flag = 1 if c >= half else (-1 if c <= -half else 0)
        if stepping and flag:
            state[FIRE + i] = state[FIRE + i] + h
        values[outputs[i]] = flag * level
        values[outputs[3 + i]] = flag
        values[outputs[6 + i]] = level
    total = 0.0
    for i in range(3):
        values[outputs[9 + i]] = state[FIRE + i]
        total = total + state[FIRE + i]
    values[outputs[12]] = total
    values[outputs[13]] = 2.0 * state[FORCE] * total / (state[ISP] * state[G0])
    return 0
