"""FMU `CircularOrbit` (instance `orbit`): analytic circular two-body orbit.

Wraps components.orbit.circular.CircularOrbit. No inputs; outputs are functions of time. The
model keeps the simulation time: the start time at initialization, t + h after do_step(t, h).
"""
import math

from neighbor_fmu_support import NeighborSlave

from components.core import constants
from components.orbit import circular


class CircularOrbit(NeighborSlave):
    description = ("Circular two-body orbit (analytic): spacecraft position and velocity in N from altitude, "
                   "inclination, RAAN and argument of latitude at the epoch")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("altitude", 420e3, "m", "Altitude above earth_radius (> 0)")
        self.parameter("inclination", math.radians(51.6), "rad", "Orbit inclination, in [0, pi]")
        self.parameter("raan", 0.0, "rad", "Right ascension of the ascending node")
        self.parameter("arg_latitude0", 0.0, "rad", "Argument of latitude at simulation time 0 (from the node)")
        self.parameter("mu", constants.MU_EARTH_WGS84, "m3/s2", "Earth's gravitational parameter (> 0)")
        self.parameter("earth_radius", constants.WGS84_A, "m", "Earth radius the altitude refers to (> 0)")
        self.output_array("r_BN_N", 3, lambda: self.model.position(), "m",
                          "Spacecraft position relative to Earth's centre in N")
        self.output_array("v_BN_N", 3, lambda: self.model.velocity(), "m/s",
                          "Spacecraft velocity relative to N, in N")
        self.output("period", lambda: self.model.period, "s", "Orbit period 2 pi sqrt(a^3 / mu)")

    def build_model(self):
        v = self.values
        return circular.CircularOrbit(v["altitude"], v["inclination"], v["raan"], v["arg_latitude0"],
                                            v["mu"], v["earth_radius"], self.start_time)


    def do_step(self, current_time, step_size):
        self.model.advance_to(current_time + step_size)
        return True
