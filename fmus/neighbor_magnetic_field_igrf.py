"""FMU `MagneticFieldIgrf` (instance `field`): Earth's main magnetic field from IGRF-14 to degree 13.

Wraps components.environment.igrf.IgrfField: the IAGA IGRF-14 Gauss coefficients (bundled
IGRF14.shc, 1900-2030, linear in time between the 5-year epochs, the predicted secular
variation after 2025), synthesized in geocentric spherical coordinates of the Earth-fixed
position (N rotated by the IAU 1982 GMST). The tilted dipole `MagneticField`'s connectors, so
`neighbor-cosim replace` swaps one for the other. B_N depends directly on the position input,
B_B on the position and the attitude. The model keeps the simulation time: the start time at
initialization, t + h after do_step(t, h).
"""
from neighbor_fmu_support import NeighborSlave, in_this_extraction

from components.environment import igrf, magnetic_field
from components.core import time_utils


class MagneticFieldIgrf(NeighborSlave):
    description = ("Geomagnetic main field IGRF-14 (IAGA, degree 13, secular variation to 2030; GMST Earth "
                   "rotation): position and attitude in, B_N and B_B in tesla out")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self._start_time = 0.0
        self.parameter("epoch", time_utils.DEFAULT_EPOCH, None,
                       "Scenario epoch (simulation time 0), ISO 8601 UTC 'YYYY-MM-DDThh:mm:ss[.fff]Z', 1900 or later",
                       str)
        self.parameter("secular_variation", True, None,
                       "True: the coefficients follow the simulation date (linear between the IGRF-14 epochs, "
                       "extrapolated after 2030); false: held at the epoch's date", bool)
        self.parameter("degree", igrf.MAX_DEGREE, None,
                       "Highest degree of the expansion, 1..13 (1: IGRF-14's own tilted dipole)", int)
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
        coefficients = in_this_extraction(igrf.COEFFICIENT_FILE, igrf, self.resources)
        return igrf.IgrfField(self.values["epoch"], self._start_time, self.values["secular_variation"],
                              self.values["degree"], coefficients)

    def setup_experiment(self, start_time, stop_time=None, tolerance=None):
        self._start_time = float(start_time)
        self._model = None

    def do_step(self, current_time, step_size):
        self.model.advance_to(current_time + step_size)
        return True

