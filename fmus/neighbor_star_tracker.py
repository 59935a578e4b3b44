"""FMU `StarTracker` (instance `star_tracker`): a star tracker's attitude with noise about and
across its boresight, Sun, Earth and Moon exclusion angles, a rate limit and an update rate.

Wraps components.sensing.adcs_sensors.StarTracker (without noise, Basilisk's starTracker: the case
frame's attitude q_CN = [CB][BN], the case turned from B by the 3-2-1 mounting angles; its
boresight is the case's +z). Invalid (valid false, the attitude held at the last valid one) when
the Sun, the Earth's disc or the Moon is within its exclusion angle of the boresight, or the body
rate exceeds max_rate; `blinded_by` says why (1 rate, 2 Sun, 4 Earth, 8 Moon, summed). With an
update_period the measurement of the last update is held; without one the outputs are the
measurement at the current inputs. One noise sample per communication step, drawn in do_step.
q_BN_meas is the body attitude the measurement gives, [BN] = [CB]^T [CN] (the mounting known).
"""
import math

import numpy as np

from neighbor_fmu_support import NeighborSlave

from components.core import rotations
from components.core.constants import ASTRONOMICAL_UNIT
from components.sensing import adcs_sensors

REASONS = {"rate": 1, "sun": 2, "earth": 4, "moon": 8}


class StarTracker(NeighborSlave):
    description = ("Star tracker: case attitude q_CN with noise about and across the boresight, Sun/Earth/Moon "
                   "exclusion angles and a rate limit (invalid flag), update rate")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter_array("mounting_321", [0.0, 0.0, 0.0], "rad",
                             "Case frame from B: 3-2-1 Euler angles yaw, pitch, roll (boresight: the case's +z)")
        self.parameter("sigma_cross", math.radians(10.0 / 3600.0), "rad",
                       "Noise standard deviation about each axis across the boresight, >= 0 (10 arcsec)")
        self.parameter("sigma_roll", math.radians(60.0 / 3600.0), "rad",
                       "Noise standard deviation about the boresight, >= 0 (60 arcsec)")
        self.parameter("sun_exclusion", math.radians(45.0), "rad", "Sun exclusion half angle from the boresight, >= 0")
        self.parameter("earth_exclusion", math.radians(20.0), "rad",
                       "Exclusion angle from the Earth's disc edge (its limb), >= 0")
        self.parameter("moon_exclusion", math.radians(10.0), "rad",
                       "Moon exclusion half angle, >= 0 (used when r_MN_N is not zero)")
        self.parameter("max_rate", math.radians(1.0), "rad/s", "Largest body rate with a solution, > 0")
        self.parameter("update_period", 0.0, "s", "Time between measurements, >= 0 (0: every communication point)")
        self.parameter("earth_radius", 6378137.0, "m", "Radius of the Earth's disc, > 0")
        self.parameter("seed", 0, None, "Seed of the noise generator numpy.random.default_rng(seed), >= 0", int)
        inputs = (self.input_array("q_BN", [0.0, 0.0, 0.0, 1.0], "1", "True attitude quaternion q_BN, scalar last")
                  + self.input_array("omega_BN_B", [0.0, 0.0, 0.0], "rad/s", "True body rate in B")
                  + self.input_array("r_BN_N", [6878137.0, 0.0, 0.0], "m", "Spacecraft position in N")
                  + self.input_array("r_SN_N", [ASTRONOMICAL_UNIT, 0.0, 0.0], "m", "Sun position in N")
                  + self.input_array("r_MN_N", [0.0, 0.0, 0.0], "m", "Moon position in N (zero: not checked)"))
        out = lambda: self.feedthrough(self._output)  # noqa: E731
        self.output_array("q_CN", 4, lambda: list(out()[0]), "1", "Measured case attitude q_CN, scalar last",
                          depends_on=inputs)
        self.output_array("q_BN_meas", 4, lambda: out()[1], "1",
                          "Measured body attitude q_BN (from q_CN and the mounting), scalar last", depends_on=inputs)
        self.output("valid", lambda: out()[2], None, "A solution: no exclusion and the rate within max_rate", bool,
                    depends_on=inputs)
        self.output("blinded_by", lambda: out()[3], None,
                    "Why no solution: 1 rate, 2 Sun, 4 Earth, 8 Moon (summed; 0 valid)", int, depends_on=inputs)

    def build_model(self):
        v = self.values
        return adcs_sensors.StarTracker(self.vector("mounting_321", 3), v["sigma_cross"], v["sigma_roll"],
                                        v["sun_exclusion"], v["earth_exclusion"], v["moon_exclusion"], v["max_rate"],
                                        v["update_period"], v["earth_radius"], v["seed"])

    def _inputs(self):
        return (self.vector("q_BN", 4), self.vector("omega_BN_B", 3), self.vector("r_BN_N", 3),
                self.vector("r_SN_N", 3), self.vector("r_MN_N", 3))

    def _output(self):
        model, inputs = self.model, self._inputs()
        q_CN, valid, reasons = model.output(*inputs)
        C_BN = model.dcm_CB.T @ np.array(rotations.attitude_matrix(q_CN))
        q_BN = rotations.dcm_to_quaternion(tuple(map(tuple, C_BN)))
        return q_CN, list(q_BN), valid, sum(REASONS[r] for r in reasons)

    def do_step(self, current_time, step_size):
        self.model.step(step_size, self._inputs())
        self._input_version += 1  # a new noise sample (and with a period, perhaps a new measurement)
        return True
