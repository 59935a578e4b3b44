"""FMU `GpsReceiver` (instance `gps`): position with seeded noise, and time.

Wraps components.sensing.sensors.GpsReceiver (thesis 3.3.1, NovAtel OEM7700 [45]). One noise sample
per communication step, drawn in do_step; r_meas_N depends directly on r_BN_N, gps_time is state.
"""
from neighbor_fmu_support import NeighborSlave

from components.sensing import sensors

class GpsReceiver(NeighborSlave):
    description = ("GPS receiver: position in N plus N(0, sigma^2) noise per axis and communication step, and the "
                   "time (NEIGHBOR thesis 3.3.1)")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("sigma", 1.5, "m", "Position noise standard deviation per axis, >= 0 (OEM7700: 1.5 m RMS)")
        self.parameter("seed", 0, None, "Seed of the noise generator numpy.random.default_rng(seed), >= 0", int)
        self.parameter("available", True, None, "Receiver has a fix; false models an outage (valid false)", bool)
        position = self.input_array("r_BN_N", [6798137.0, 0.0, 0.0], "m", "True spacecraft position in N")
        self.output_array("r_meas_N", 3, lambda: self.feedthrough(self._measure)[0], "m",
                          "Measured position in N (zeros when invalid)", depends_on=position)
        # not named `time`: FMPy's result arrays (and CSV files) already have a `time` column
        self.output("gps_time", lambda: self.model.time, "s",
                    "Time of the measurement (the simulation time): seconds since the scenario epoch")
        self.output("valid", lambda: self.model.available, None, "Position and time valid", bool)


    def build_model(self):
        return sensors.GpsReceiver(self.values["sigma"], self.values["seed"], self.values["available"],
                                   self.start_time)

    def _measure(self):
        return self.model.measure(self.vector("r_BN_N", 3))

    def do_step(self, current_time, step_size):
        self.model.step(step_size, current_time + step_size)
        self._input_version += 1  # new noise sample: recompute the outputs
        return True
