"""FMU `EarthShadow` (instance `shadow`): conical umbra/penumbra Earth shadow.

Wraps components.environment.eclipse.EarthShadow (Montenbruck and Gill, section 3.4.2). Stateless: every
output depends directly on both position inputs.
"""
from neighbor_fmu_support import NeighborSlave

from components.core import constants
from components.environment import eclipse


class EarthShadow(NeighborSlave):
    description = ("Earth shadow, conical umbra/penumbra model (Montenbruck and Gill 3.4.2): fraction of the "
                   "Sun's disk visible from the spacecraft, umbra/penumbra flags and orbit day")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("earth_radius", constants.WGS84_A, "m", "Radius of the spherical Earth (> 0)")
        self.parameter("sun_radius", eclipse.SUN_RADIUS, "m", "Radius of the Sun (> 0)")
        self.parameter("day_threshold", eclipse.DAY_THRESHOLD, "1",
                       "orbit_day is true when sunlit_fraction exceeds this value, in [0, 1)")
        position = self.input_array("r_BN_N", [constants.WGS84_A + 420e3, 0.0, 0.0], "m",
                                    "Spacecraft position relative to Earth's centre in N")
        sun = self.input_array("r_SN_N", [constants.ASTRONOMICAL_UNIT, 0.0, 0.0], "m",
                               "Sun position relative to Earth's centre in N")
        deps = position + sun
        f = lambda: self.feedthrough(self._evaluate)  # noqa: E731
        self.output("sunlit_fraction", lambda: f()[0], "1",
                    "Fraction of the Sun's disk visible: 1 full Sun, 0 umbra, between in penumbra", depends_on=deps)
        self.output("umbra", lambda: f()[1], None, "In the umbra (sunlit_fraction = 0)", bool, depends_on=deps)
        self.output("penumbra", lambda: f()[2], None,
                    "Partly shadowed, 0 < sunlit_fraction < 1 (penumbra, or annular beyond the umbra's apex)",
                    bool, depends_on=deps)
        self.output("orbit_day", lambda: f()[3], None, "sunlit_fraction > day_threshold", bool, depends_on=deps)

    def build_model(self):
        return eclipse.EarthShadow(self.values["earth_radius"], self.values["sun_radius"],
                                   self.values["day_threshold"])

    def _evaluate(self):
        return self.model.evaluate(self.vector("r_BN_N", 3), self.vector("r_SN_N", 3))

    def do_step(self, current_time, step_size):
        return True
