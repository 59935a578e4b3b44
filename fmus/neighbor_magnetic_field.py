"""FMU `MagneticField` (instance `field`): Earth's magnetic field as a tilted dipole.

Wraps components.environment.magnetic_field.MagneticField: the first-degree IGRF-13 Gauss coefficients
(epoch 2020.0: g10 = -29404.8, g11 = -1450.9, h11 = 4652.5 nT; Alken et al. 2021), the
Earth-fixed frame from N by the IAU 1982 GMST. B_N depends directly on the position input,
B_B on the position and the attitude. The model keeps the simulation time: the start time at
initialization, t + h after do_step(t, h).
"""
from neighbor_fmu_support import NeighborSlave

from components.environment import magnetic_field
from components.core import time_utils


class MagneticField(NeighborSlave):
    description = ("Geomagnetic field as a tilted dipole (IGRF-13 2020.0 first-degree Gauss coefficients, "
                   "GMST Earth rotation): position and attitude in, B_N and B_B in tesla out")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self._start_time = 0.0
        self.parameter("epoch", time_utils.DEFAULT_EPOCH, None,
                       "Scenario epoch (simulation time 0), ISO 8601 UTC 'YYYY-MM-DDThh:mm:ss[.fff]Z'", str)
        self.parameter("secular_variation", False, None,
                       "True: apply the IGRF-13 secular variation (dg10 = 5.7, dg11 = 7.4, dh11 = -25.9 nT/yr) "
                       "from 2020.0 to the current date; false: the 2020.0 coefficients", bool)
        position = self.input_array("r_BN_N", [magnetic_field.R_REF + 500e3, 0.0, 0.0], "m",
                                    "Spacecraft position relative to Earth's centre in N (must be non-zero)")
        quaternion = self.input_array("q_BN", [0.0, 0.0, 0.0, 1.0], "1",
                                      "Attitude quaternion of B relative to N, scalar last (normalized before use)")
        self.output_array("B_N", 3, self._field_N, "T",
                          "Geomagnetic field at the spacecraft in N", depends_on=position)
        self.output_array("B_B", 3, self._field_B, "T",
                          "Geomagnetic field at the spacecraft in B, A(q_BN) B_N", depends_on=position + quaternion)

    def _field_N(self):
        return self.model.field_N(self.vector("r_BN_N", 3))

    def _field_B(self):
        return self.model.field_B(self.vector("r_BN_N", 3), self.vector("q_BN", 4))

    def build_model(self):
        return magnetic_field.MagneticField(self.values["epoch"], self._start_time,
                                            self.values["secular_variation"])

    def setup_experiment(self, start_time, stop_time=None, tolerance=None):
        self._start_time = float(start_time)
        self._model = None

    def do_step(self, current_time, step_size):
        self.model.advance_to(current_time + step_size)
        return True
