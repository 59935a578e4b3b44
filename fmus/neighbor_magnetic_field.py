"""FMU `MagneticField` (instance `field`): Earth's magnetic field as a tilted dipole.

Wraps components.environment.magnetic_field.MagneticField: the first-degree IGRF-13 Gauss coefficients
(epoch 2020.0: g10 = -29404.8, g11 = -1450.9, h11 = 4652.5 nT; Alken et al. 2021), the
Earth-fixed frame from N by the IAU 1982 GMST. B_N depends directly on the position input,
B_B on the position and the attitude. The model keeps the simulation time: the start time at
initialization, t + h after do_step(t, h). The connectors are MagneticFieldIgrf's
(neighbor_field_support).
"""
from neighbor_field_support import FieldSlave

from components.environment import magnetic_field


class MagneticField(FieldSlave):
    description = ("Geomagnetic field as a tilted dipole (IGRF-13 2020.0 first-degree Gauss coefficients, "
                   "GMST Earth rotation): position and attitude in, B_N and B_B in tesla out")

    def __init__(self, **kwargs):
        super().__init__("Scenario epoch (simulation time 0), ISO 8601 UTC 'YYYY-MM-DDThh:mm:ss[.fff]Z'",
                         "True: apply the IGRF-13 secular variation (dg10 = 5.7, dg11 = 7.4, dh11 = -25.9 nT/yr) "
                         "from 2020.0 to the current date; false: the 2020.0 coefficients", False, **kwargs)

    def build_model(self):
        return magnetic_field.MagneticField(self.values["epoch"], self._start_time,
                                            self.values["secular_variation"])
