"""FMU `SlewController` (instance `slew`): quaternion-error PD with thruster thresholds.

Wraps components.attitude.slew.SlewController (thesis Eq. 41-46, Appendix C `Slew`, stop test of
Appendix E, or of Appendix G with accept_antipodal). Stateless.
"""
import math

from neighbor_fmu_support import NeighborSlave

from components.core import rotations
from components.attitude import slew, thruster_control

Q_INPUTS = [f"q_BN[{i}]" for i in (1, 2, 3, 4)]
RATE_INPUTS = [f"omega_BN_B[{i}]" for i in (1, 2, 3)]


class SlewController(NeighborSlave):
    description = ("Slew controller: quaternion-error PD quantized to RCS thruster-pair torques (NEIGHBOR thesis "
                   "Eq. 41-46); done when attitude and rates are within tolerance (Appendix E/G)")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter_array("Kp", [10.0] * 3, "N.m", "Proportional gain on the error quaternion (Eq. 45)")
        self.parameter_array("Kd", [17.5] * 3, "N.m.s", "Derivative gain on the rate error (Eq. 45)")
        self.parameter_array("q_d", [0.0, 0.0, 0.0, 1.0], "1", "Target attitude quaternion q_BN, scalar last")
        self.parameter_array("omega_d", [0.0] * 3, "rad/s", "Desired angular velocity at the target")
        self.parameter("q_tol", 0.01, "1", "Tolerance on each quaternion element for done (> 0)")
        self.parameter_array("omega_tol", [math.radians(0.01)] * 3, "rad/s", "Rate tolerance for done (> 0)")
        self.parameter_array("torque_level", thruster_control.pair_torques(), "N.m",
                             "Torque of one thruster pair per axis (Eq. 16, > 0)")
        self.parameter("accept_antipodal", False, None,
                       "True: done also when each element matches -q_d (Appendix G); false: q_d only (Appendix E)",
                       bool)
        self.thruster_controller_interface(
            self._command, self._done, Q_INPUTS + RATE_INPUTS, Q_INPUTS + RATE_INPUTS,
            "Slew complete: quaternion and rates within tolerance (Appendix E/G stop test)")
        self.output("attitude_error", lambda: self.feedthrough(self._angle), "rad",
                    "Rotation angle from the current to the target attitude, 2 acos|dq4|", depends_on=Q_INPUTS)

    def build_model(self):
        return slew.SlewController(self.vector("Kp", 3), self.vector("Kd", 3), self.vector("q_d", 4),
                                   self.vector("omega_d", 3), self.values["q_tol"], self.vector("omega_tol", 3),
                                   self.vector("torque_level", 3), self.values["accept_antipodal"])

    def _command(self):
        return self.model.command(self.vector("q_BN", 4), self.vector("omega_BN_B", 3))

    def _done(self):
        return self.model.done(self.vector("q_BN", 4), self.vector("omega_BN_B", 3))

    def _angle(self):
        dq = rotations.normalized(self.model.error_quaternion(self.vector("q_BN", 4)), "q_BN")
        return 2.0 * math.acos(min(1.0, abs(dq[3])))

    def do_step(self, current_time, step_size):
        return True
