"""RCS thruster pairs: applied torque, firing time and propellant (thesis Eq. 13-16, 74).

The commanded torque is rounded per axis to the nearest available level {-L, 0, +L}
(L from the geometry, Eq. 16), so a controller's already-quantized command passes through
unchanged and any other command maps to what the hardware can do. While a pair fires its
firing time accumulates; propellant follows Eq. 74 with the impulse of two thrusters:

    m_p = 2 F t_fire / (Isp g0)        (Appendix D/E `mpDetumble`, `mpSlew`)

where t_fire is summed over the three axes (the scripts add dt once per firing axis).
"""
import math

from ..mission.neighbor import SPACECRAFT
from . import thruster_control as tc


class ThrusterPairs:
    def __init__(self, force=tc.F_THRUSTER, a=SPACECRAFT.edge_a, c=SPACECRAFT.edge_c, isp=SPACECRAFT.isp,
                 g0=SPACECRAFT.g0):
        self.levels = tc.pair_torques(force, a, c)
        for name, value in (("Isp", isp), ("g0", g0)):
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"{name} = {value!r} must be a finite positive number")
        self.force, self.isp, self.g0 = float(force), float(isp), float(g0)
        self.fire_time = [0.0, 0.0, 0.0]

    def flags(self, command):
        """-1/0/+1 per axis: nearest available level to the commanded torque."""
        return tc.nearest_pair_flags(command, self.levels)

    def applied_torque(self, command):
        return [f * lvl for f, lvl in zip(self.flags(command), self.levels)]

    def step(self, command, h):
        for i, f in enumerate(self.flags(command)):
            if f:
                self.fire_time[i] += h

    def total_fire_time(self):
        return sum(self.fire_time)

    def propellant_mass(self):
        return 2.0 * self.force * self.total_fire_time() / (self.isp * self.g0)

    def get_state(self):
        return {"fire_time": list(self.fire_time)}

    def set_state(self, state):
        self.fire_time = list(state["fire_time"])
