"""FMU `ReferenceTrackingController` (instance `tracker`): PD + feed-forward tracking of a
moving attitude reference.

Wraps components.attitude.reference_tracking.ReferenceTrackingController. Same controller connectors as
`SlewController` (q_BN, omega_BN_B, enabled in; torque_cmd_B, thrust_flag, done out) plus the
reference inputs from a guidance FMU. Continuous (clipped) torque by default, thruster
threshold logic with quantize = true. Stateless.
"""
import math

from neighbor_fmu_support import NeighborSlave

from components.attitude import reference_tracking as rt


class ReferenceTrackingController(NeighborSlave):
    description = ("Reference-tracking attitude controller: feed-forward torque plus quaternion-error PD to a moving "
                   "reference, continuous (clipped) or quantized to thruster-pair torques")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter_array("Kp", list(rt.DEFAULT_KP), "N.m", "Proportional gain on the error quaternion (>= 0)")
        self.parameter_array("Kd", list(rt.DEFAULT_KD), "N.m.s", "Derivative gain on the rate error (>= 0)")
        self.parameter_array("max_torque", [0.0025] * 3, "N.m",
                             "Torque limit per axis (> 0): clip level, or the pair torque when quantize is true")
        self.parameter("quantize", False, None,
                       "True: thruster threshold logic (+-max_torque or 0); false: continuous torque clipped to "
                       "+-max_torque", bool)
        self.parameter("angle_tol", math.radians(0.1), "rad", "Attitude error angle tolerance for done, in (0, pi)")
        self.parameter("rate_tol", math.radians(0.01), "rad/s", "Rate error tolerance per axis for done (> 0)")
        q = self.input_array("q_BN", [0.0, 0.0, 0.0, 1.0], "1", "Measured attitude quaternion q_BN, scalar last")
        omega = self.input_array("omega_BN_B", [0.0] * 3, "rad/s", "Measured angular velocity of B relative to N, in B")
        q_ref = self.input_array("q_ref_BN", [0.0, 0.0, 0.0, 1.0], "1",
                                 "Reference attitude quaternion q_BN, scalar last")
        omega_ref = self.input_array("omega_ref_BN_B", [0.0] * 3, "rad/s", "Reference angular velocity, in B")
        torque_ff = self.input_array("torque_ff_B", [0.0] * 3, "N.m", "Feed-forward torque from the guidance, in B")
        guidance_done = self.input("guidance_done", False, None, "The guidance profile has ended", bool)
        enabled = self.input("enabled", True, None, "Controller enabled; when false it commands zero torque", bool)

        deps = q + omega + q_ref + omega_ref + torque_ff + (enabled,)
        cmd = lambda: self.feedthrough(self._command)  # noqa: E731
        self.output_array("torque_cmd_B", 3, lambda: cmd()[0], "N.m",
                          "Commanded body torque: continuous, clipped to +-max_torque (quantize false), or "
                          "+-max_torque / 0 (quantize true)", depends_on=deps)
        self.output_array("thrust_flag", 3, lambda: cmd()[1], None,
                          "Sign of the commanded torque per axis: 1 positive, -1 negative, 0 none", int,
                          depends_on=deps)
        done_deps = q + omega + q_ref + omega_ref + (guidance_done,)
        self.output("done", lambda: self.feedthrough(self._done), None,
                    "Guidance done and attitude error <= angle_tol and every rate error <= rate_tol", bool,
                    depends_on=done_deps)
        self.output("attitude_error", lambda: self.feedthrough(self._angle), "rad",
                    "Rotation angle from the reference to the measured attitude, 2 acos|dq4|",
                    depends_on=q + q_ref)

    def build_model(self):
        v = self.values
        return rt.ReferenceTrackingController(self.vector("Kp", 3), self.vector("Kd", 3), self.vector("max_torque", 3),
                                              v["quantize"], v["angle_tol"], v["rate_tol"])

    def _command(self):
        if not self.values["enabled"]:
            return [0.0, 0.0, 0.0], [0, 0, 0]
        return self.model.command(self.vector("q_BN", 4), self.vector("omega_BN_B", 3), self.vector("q_ref_BN", 4),
                                  self.vector("omega_ref_BN_B", 3), self.vector("torque_ff_B", 3))

    def _done(self):
        return self.model.done(self.vector("q_BN", 4), self.vector("omega_BN_B", 3), self.vector("q_ref_BN", 4),
                               self.vector("omega_ref_BN_B", 3), self.values["guidance_done"])

    def _angle(self):
        return self.model.error_angle(self.vector("q_BN", 4), self.vector("q_ref_BN", 4))

    def do_step(self, current_time, step_size):
        return True
