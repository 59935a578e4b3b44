"""FMU `SunlineEphemeris` (instance `sunline`): Sun heading in B from ephemeris (the sunline module description).

Wraps components.sensing.sunline.SunlineEphemeris: d_N = (r_SN_N - r_BN_N)/|r_SN_N - r_BN_N|,
d_B = [BN(sigma_BN)] d_N, or A(q_BN) d_N with attitude_input = "quaternion". Stateless; both
outputs are direct feedthrough of the inputs.
"""
from neighbor_fmu_support import NeighborSlave

from components.core.constants import ASTRONOMICAL_UNIT as AU
from components.sensing import sunline


class SunlineEphemeris(NeighborSlave):
    description = ("Sunline from ephemeris: unit Sun heading in the body frame from the Sun and spacecraft "
                   "positions and the attitude (MRP sigma_BN or quaternion q_BN), d_B = [BN] (r_sun - r_sc)/|...|")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("attitude_input", "mrp", None,
                       "Attitude input used: 'mrp' (sigma_BN, the default) or 'quaternion' (q_BN)", str)
        sun = self.input_array("r_SN_N", [AU, 0.0, 0.0], "m", "Sun position in N")
        position = self.input_array("r_BN_N", [0.0, 0.0, 0.0], "m", "Spacecraft position in N")
        sigma = self.input_array("sigma_BN", [0.0, 0.0, 0.0], "1",
                                 "Attitude MRP sigma_BN (Schaub and Junkins), used when attitude_input = 'mrp'")
        quaternion = self.input_array("q_BN", [0.0, 0.0, 0.0, 1.0], "1",
                                      "Attitude quaternion q_BN, scalar last, used when attitude_input = 'quaternion'")
        self.output_array("sun_heading_B", 3, lambda: self.feedthrough(self._heading)[0], "1",
                          "Unit vector from the spacecraft to the Sun in B",
                          depends_on=sun + position + sigma + quaternion)
        self.output("sun_distance", lambda: self.feedthrough(self._heading)[1], "m",
                    "Distance from the spacecraft to the Sun, |r_SN_N - r_BN_N|", depends_on=sun + position)

    def build_model(self):
        return sunline.SunlineEphemeris(self.values["attitude_input"])

    def _heading(self):
        v = self.vector
        return self.model.heading(v("r_SN_N", 3), v("r_BN_N", 3), v("sigma_BN", 3), v("q_BN", 4))

    def do_step(self, current_time, step_size):
        return True
