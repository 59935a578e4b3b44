"""FMU `BurnGuidance` (instance `guidance`): the de-orbit burn attitude from the actual orbit.

Wraps components.attitude.burn_guidance.burn_frame: from the orbit's position and velocity,
the attitude with the thrust axis +x_B along -v, y_B along the orbit normal and z_B towards
nadir, and the rate at which that frame turns (|r x v| / |r|^2 about y_B). Direct
feedthrough, stateless. The slew and tracking controllers take it as their target
(`target_from_input`), so the burn attitude follows the orbit in every scenario.
"""
from neighbor_fmu_support import NeighborSlave

from components.attitude import burn_guidance


class BurnGuidance(NeighborSlave):
    description = ("De-orbit burn guidance: anti-velocity burn attitude (thrust axis +x_B along -v, y_B along the "
                   "orbit normal) and its rate from the orbit's position and velocity; direct feedthrough")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        position = self.input_array("r_BN_N", [6798136.3, 0.0, 0.0], "m",
                                    "Spacecraft position relative to Earth's centre in N")
        velocity = self.input_array("v_BN_N", [0.0, 4750.0, 6000.0], "m/s",
                                    "Spacecraft velocity relative to N, in N (not parallel to r_BN_N)")
        self.output_array("q_target_BN", 4, lambda: self.feedthrough(self._frame)[0], "1",
                          "Burn attitude quaternion q_BN, scalar last (q4 >= 0): +x_B along -v, +y_B along r x v",
                          depends_on=position + velocity)
        self.output_array("omega_target_B", 3, lambda: self.feedthrough(self._frame)[1], "rad/s",
                          "Angular velocity of the burn frame in B: |r x v| / |r|^2 about y_B (the mean motion on a "
                          "circular orbit, thesis Eq. 67-68 at the actual radius)", depends_on=position + velocity)

    def build_model(self):
        return burn_guidance.BurnGuidance()

    def _frame(self):
        return self.model.frame(self.vector("r_BN_N", 3), self.vector("v_BN_N", 3))

    def do_step(self, current_time, step_size):
        return True
