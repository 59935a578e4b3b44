"""FMU `Atmosphere`: atmospheric mass density and geodetic altitude at a position.

Wraps components.environment.atmosphere (exponential, Harris-Priester, NRLMSIS 2.1 or Jacchia-Roberts, with
space weather from a CSSI file or constant indices; see that module). Input: the spacecraft
position r_BN_N (m, N frame); outputs: density (kg/m3) and geodetic altitude above WGS-84 (m),
both direct feedthrough of the position at the current time. The model keeps the simulation
time: the start time at initialization, t + h after do_step(t, h).

Harris-Priester exponent: this FMU knows no orbit, so hp_exponent = 0 means n = 4.
"""
from neighbor_fmu_support import NeighborSlave
from neighbor_orbit_support import atmosphere_model, atmosphere_parameters

from components.core import jit
from components.environment import atmosphere
from components.core import time_utils
from components.core.constants import R_EQ


class Atmosphere(NeighborSlave):
    description = ("Atmosphere density at the spacecraft position: exponential (Vallado), Harris-Priester, "
                   "NRLMSIS 2.1 or Jacchia-Roberts with CSSI space weather or constant indices")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.log(f"density and orbit kernels: {jit.describe()}")
        self.parameter("epoch", time_utils.DEFAULT_EPOCH, None,
                       "Scenario epoch (simulation time 0), ISO 8601 UTC 'YYYY-MM-DDThh:mm:ss[.fff]Z'", str)
        atmosphere_parameters(self)
        position = self.input_array("r_BN_N", [R_EQ + 420e3, 0.0, 0.0], "m",
                                    "Spacecraft position relative to Earth's centre in N")
        self.output("density", lambda: self.feedthrough(self._density), "kg/m3",
                    "Atmospheric mass density at r_BN_N at the current time", depends_on=position)
        self.output("altitude", lambda: self.feedthrough(self._altitude), "m",
                    "Geodetic altitude of r_BN_N above the WGS-84 ellipsoid", depends_on=position)

    def _density(self):
        return self.model.density(self.vector("r_BN_N", 3))

    def _altitude(self):
        return self.model.altitude(self.vector("r_BN_N", 3))

    def build_model(self):
        model = atmosphere_model(self.values, resources=self.resources)
        return atmosphere.AtmosphereAtEpoch(model, self.values["epoch"], self.start_time)

    def do_step(self, current_time, step_size):
        self.model.advance_to(current_time + step_size)
        self._input_version += 1  # outputs depend on time too: drop the feedthrough cache
        return True
