"""FMU `SlewController` (instance `slew`): quaternion-error PD with thruster thresholds.

Wraps components.attitude.slew.SlewController (thesis Eq. 41-46, Appendix C `Slew`, stop test of
Appendix E, or of Appendix G with accept_antipodal).

Flight options (appended after the thesis' variables, so their value references are unchanged):
`target_from_input` takes the target from the inputs q_target_BN and omega_target_B (the burn
guidance) instead of the parameters q_d and omega_d; `rate_deadband` raises the firing threshold
to an impulse bit; `settle_time` > 0 ends the slew once the error angle is within settle_angle
and the rates within omega_tol for that long. State: the time the stop test has held.
"""
import math

from neighbor_fmu_support import TARGET_INPUTS, NeighborSlave

from components.attitude import slew, thruster_control


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
        reads = lambda s: s.q_BN + s.omega_BN_B + TARGET_INPUTS  # noqa: E731
        ctl = self.thruster_controller_interface(
            self._command, self._done, reads, reads,
            "Slew complete: quaternion and rates within tolerance (Appendix E/G stop test; with settle_time, "
            "error angle and rates held within tolerance for settle_time)")
        self.output("attitude_error", lambda: self.feedthrough(self._angle), "rad",
                    "Rotation angle from the current to the target attitude, 2 acos|dq4|",
                    depends_on=ctl.q_BN + TARGET_INPUTS)
        self.parameter("target_from_input", False, None,
                       "True: target from the inputs q_target_BN and omega_target_B (burn guidance); false: the "
                       "fixed parameters q_d and omega_d (the thesis cases)", bool)
        self.target_inputs("used when target_from_input")
        self.parameter_array("rate_deadband", [0.0] * 3, "rad/s",
                             "Flight option: a pair fires only when |command| / Kd exceeds this (>= 0; one impulse "
                             "bit lets a pulse end inside it); 0: the thesis threshold, the pair torque")
        self.parameter("settle_time", 0.0, "s",
                       "Settle criterion: done once the error angle is within settle_angle and the rates within "
                       "omega_tol for this long (>= 0); 0: the thesis' single-sample element test")
        self.parameter("settle_angle", math.radians(1.0), "rad",
                       "Attitude error angle for the settle criterion, in (0, pi] (used when settle_time > 0)")

    def build_model(self):
        return slew.SlewController(self.vector("Kp", 3), self.vector("Kd", 3), self.vector("q_d", 4),
                                   self.vector("omega_d", 3), self.values["q_tol"], self.vector("omega_tol", 3),
                                   self.vector("torque_level", 3), self.values["accept_antipodal"],
                                   self.vector("rate_deadband", 3), self.values["settle_time"],
                                   self.values["settle_angle"])

    def _targeted(self):
        """The model, its target taken from the inputs when target_from_input and enabled (a
        disabled controller's inputs are not refreshed by a master that suspends it)."""
        if self.values["target_from_input"] and self.values["enabled"]:
            self.model.set_target(self.vector("q_target_BN", 4), self.vector("omega_target_B", 3))
        return self.model

    def _command(self):
        return self._targeted().command(self.vector("q_BN", 4), self.vector("omega_BN_B", 3))

    def _done(self):
        return self._targeted().done(self.vector("q_BN", 4), self.vector("omega_BN_B", 3))

    def _angle(self):
        return self._targeted().attitude_error(self.vector("q_BN", 4))

    def do_step(self, current_time, step_size):
        self._targeted().advance(self.vector("q_BN", 4), self.vector("omega_BN_B", 3), step_size,
                                 self.values["enabled"])
        self._input_version += 1  # the settle count changed: `done` computed before the step is stale
        return True
