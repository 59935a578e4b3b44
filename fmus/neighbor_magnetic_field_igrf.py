"""FMU `MagneticFieldIgrf` (instance `field`): Earth's main magnetic field from IGRF-14 to degree 13.

Wraps components.environment.igrf.IgrfField: the IAGA IGRF-14 Gauss coefficients (bundled
IGRF14.shc, 1900-2030, linear in time between the 5-year epochs, the predicted secular
variation after 2025), synthesized in geocentric spherical coordinates of the Earth-fixed
position (N rotated by the IAU 1982 GMST). The tilted dipole `MagneticField`'s connectors
(neighbor_field_support), so `neighbor-cosim replace` swaps one for the other. B_N depends
directly on the position input, B_B on the position and the attitude. The model keeps the
simulation time: the start time at initialization, t + h after do_step(t, h).
"""
from neighbor_field_support import FieldSlave
from neighbor_fmu_support import in_this_extraction

from components.environment import igrf


class MagneticFieldIgrf(FieldSlave):
    description = ("Geomagnetic main field IGRF-14 (IAGA, degree 13, secular variation to 2030; GMST Earth "
                   "rotation): position and attitude in, B_N and B_B in tesla out")

    def __init__(self, **kwargs):
        super().__init__("Scenario epoch (simulation time 0), ISO 8601 UTC 'YYYY-MM-DDThh:mm:ss[.fff]Z', 1900 or "
                         "later", "True: the coefficients follow the simulation date (linear between the IGRF-14 "
                         "epochs, extrapolated after 2030); false: held at the epoch's date", True, **kwargs)
        self.parameter("degree", igrf.MAX_DEGREE, None,
                       "Highest degree of the expansion, 1..13 (1: IGRF-14's own tilted dipole)", int)

    def build_model(self):
        coefficients = in_this_extraction(igrf.COEFFICIENT_FILE, igrf, self.resources)
        return igrf.IgrfField(self.values["epoch"], self._start_time, self.values["secular_variation"],
                              self.values["degree"], coefficients)
