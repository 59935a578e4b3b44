"""FMU `SunEphemeris` (instance `sun`): position of the Sun relative to Earth's centre.

Wraps components.environment.sun.SunEphemeris (Astronomical Almanac / Vallado Algorithm 29 low-precision
Sun, about 0.01 deg). No inputs; the output is a function of time only. The model keeps the
simulation time: the start time at initialization, t + h after do_step(t, h).
"""
from neighbor_fmu_support import NeighborSlave

from components.environment import sun
from components.core import time_utils


class SunEphemeris(NeighborSlave):
    description = ("Sun ephemeris: position of the Sun relative to Earth's centre, r_SN_N in m (Astronomical "
                   "Almanac low-precision formulae, Vallado Algorithm 29, about 0.01 deg)")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("epoch", time_utils.DEFAULT_EPOCH, None,
                       "Scenario epoch (simulation time 0), ISO 8601 UTC 'YYYY-MM-DDThh:mm:ss[.fff]Z'", str)
        self.output_array("r_SN_N", 3, lambda: self.model.position(), "m",
                          "Position of the Sun relative to Earth's centre in N (mean equator and equinox of "
                          "date, used as J2000 axes)")

    def build_model(self):
        return sun.SunEphemeris(self.values["epoch"], self.start_time)


    def do_step(self, current_time, step_size):
        self.model.advance_to(current_time + step_size)
        return True
