"""FMU `MrpFeedback` (instance `control`): Schaub's MRP feedback law for a spacecraft with reaction
wheels (Basilisk's mrpFeedback), the body torque command from the attitude tracking error.

Wraps components.attitude.mrp_feedback.MrpFeedback: gains K, P, the optional integral term (Ki,
integral_limit), the spacecraft's inertia (wheels included) and the wheels' spin momentum for the
gyroscopic term. torque_cmd_B is the torque the body is to feel (for WheelTorqueDistribution, or
for magnetorquers); it depends directly on the tracking error and the wheel momentum. The integral
is the law's state, updated at each step's end. `enabled` (a mode manager's switch, e.g.
AdcsModeSequence) false: zero torque, and the integral restarts from zero.
"""
import numpy as np
from neighbor_fmu_support import NeighborSlave

from components.attitude import mrp_feedback, rigid_body


class MrpFeedback(NeighborSlave):
    description = ("MRP feedback attitude law (Schaub; Basilisk's mrpFeedback): body torque command from the "
                   "attitude tracking error, with gyroscopic, feed-forward and optional integral terms")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("K", 0.0005, "N.m", "Attitude (MRP) gain, > 0")
        self.parameter("P", 0.01, "N.m.s", "Rate gain, > 0")
        self.parameter("Ki", 0.0, "1/s", "Integral gain, >= 0 (0: no integral term)")
        self.parameter("integral_limit", 0.0, "N.m.s", "Limit on each component of the integrated attitude error "
                       "K int(sigma dt), > 0 with Ki > 0")
        self.parameter("control_law", 0, None, "Gyroscopic term: 0 with omega_RN_B + Ki z, 1 with omega_BN_B", int)
        # the spacecraft's inertia, wheels included: the parameters RigidBody and the RCS controllers share
        self.inertia_parameters("Spacecraft mass (the box inertia's)")
        self.parameter_array("known_torque_B", [0.0, 0.0, 0.0], "N.m", "Known external torque to cancel (feed-forward)")
        error = (self.input_array("sigma_BR", [0.0] * 3, "1", "Attitude error: MRP of B relative to R")
                 + self.input_array("omega_BR_B", [0.0] * 3, "rad/s", "Body rate relative to the reference, in B")
                 + self.input_array("omega_RN_B", [0.0] * 3, "rad/s", "Reference rate relative to N, in B")
                 + self.input_array("domega_RN_B", [0.0] * 3, "rad/s2",
                                    "Reference angular acceleration relative to N, in B"))
        wheels = self.input_array("wheel_momentum_B", [0.0] * 3, "N.m.s",
                                  "Wheels' absolute spin momentum in B (ReactionWheelArray; 0 without wheels)")
        out = lambda: self.feedthrough(self._evaluate)  # noqa: E731
        self.output_array("torque_cmd_B", 3, lambda: out()[0].tolist(), "N.m",
                          "Commanded torque on the body in B (-Lr)", depends_on=error + wheels)
        self.output_array("integral_torque_B", 3, lambda: out()[1].tolist(), "N.m",
                          "The integral term's part of torque_cmd_B (-P Ki z)", depends_on=error)
        # appended last (existing systems keep their value references); a mode manager's switch
        enabled = self.input("enabled", True, None, "Law enabled; when false the command is zero and the integral "
                             "restarts from zero", bool)
        self.add_dependencies(("torque_cmd_B", "integral_torque_B"), (enabled,))

    def build_model(self):
        v = self.values
        return mrp_feedback.MrpFeedback(self.inertia(rigid_body.box_inertia), v["K"], v["P"], v["Ki"],
                                        v["integral_limit"], v["control_law"], self.vector("known_torque_B", 3))

    def _evaluate(self):
        if not self.values["enabled"]:
            return np.zeros(3), np.zeros(3)
        return self.model.torque(self.vector("sigma_BR", 3), self.vector("omega_BR_B", 3),
                                 self.vector("omega_RN_B", 3), self.vector("domega_RN_B", 3),
                                 self.vector("wheel_momentum_B", 3))

    def do_step(self, current_time, step_size):
        if self.values["enabled"]:
            self.model.step(self.vector("sigma_BR", 3), step_size)
        else:
            self.model.reset()
        self._input_version += 1  # the integral changed
        return True
