"""FMU `TrackingController` (instance `tracking`): de-orbit attitude tracking (sliding mode).

Wraps components.attitude.deorbit_tracking.DeorbitTrackingController (thesis Eq. 67-73, Appendix C
`Deorbit` and `TargetQuaternion`, Appendix F). Same thruster-controller connectors as the slew
and detumble controllers (`enabled`, `torque_cmd_B[3]`, `thrust_flag[3]`, `done`), so a system
swaps controllers by switching `enabled`; thrust time and propellant are counted by RcsThrusters.

State: the desired quaternion q_d. With q_d_from_measured (default, Appendix F `q_d = q`) it is
latched from the q_BN input at the first step while enabled (before that the outputs use
q_d = q_BN) and released while disabled; otherwise it starts at q_d0 and is propagated every
step. Each do_step propagates it at omega_d over the communication step (Eq. 19-21).
"""
from neighbor_fmu_support import NeighborSlave

from components.attitude import deorbit_tracking, rigid_body, thruster_control

Q_INPUTS = [f"q_BN[{i}]" for i in (1, 2, 3, 4)]
RATE_INPUTS = [f"omega_BN_B[{i}]" for i in (1, 2, 3)]


class TrackingController(NeighborSlave):
    description = ("De-orbit attitude tracking: sliding-mode control (NEIGHBOR thesis Eq. 67-73) of an attitude "
                   "turning once per orbit about body y, quantized to RCS thruster-pair torques")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("k", 1.0, "rad/s", "Sliding-surface gain k on the error quaternion (Eq. 70, 73; > 0)")
        self.parameter_array("G", [0.1] * 3, "rad/s2", "Diagonal of the gain matrix G (Eq. 72-73; > 0)")
        self.parameter_array("e", [0.001] * 3, "rad/s", "Saturation thresholds epsilon of s_bar (Eq. 71, 73; > 0)")
        self.parameter_array("omega_d", deorbit_tracking.default_omega_d(), "rad/s",
                             "Desired angular velocity in B: one turn per orbit period at Re + 400 km about y "
                             "(Eq. 67-68)")
        self.parameter_array("omega_dot_d", [0.0] * 3, "rad/s2", "Desired angular acceleration in B (Eq. 72)")
        self.parameter("q_d_from_measured", True, None,
                       "True: q_d latched from q_BN at the first enabled step (Appendix F), released while "
                       "disabled; false: q_d starts at q_d0 at the start of the run", bool)
        self.parameter_array("q_d0", [0.0, 0.0, 0.0, 1.0], "1",
                             "Initial desired quaternion q_BN, scalar last (used when q_d_from_measured is false)")
        self.inertia_parameters("Spacecraft mass for the box inertia the law uses (Eq. 4)")
        self.parameter_array("torque_level", thruster_control.pair_torques(), "N.m",
                             "Torque of one thruster pair per axis (Eq. 16, > 0)")
        self.thruster_controller_interface(
            self._command, self._done, Q_INPUTS + RATE_INPUTS, Q_INPUTS + RATE_INPUTS,
            "Tracking converged: every sliding-vector component within its threshold e (the burn itself "
            "ends on the propellant budget, not on this signal)")
        self.output("attitude_error", lambda: self.feedthrough(self._angle), "rad",
                    "Rotation angle from the desired to the current attitude, 2 acos|dq4|", depends_on=Q_INPUTS)
        self.output("pointing_error", lambda: self.feedthrough(self._pointing), "rad",
                    "Angle between the body x axis (de-orbit thrust axis) and the desired x axis",
                    depends_on=Q_INPUTS)
        self.output_array("q_d", 4, lambda: self.feedthrough(self._target), "1",
                          "Desired quaternion q_BN, scalar last (equals q_BN while the latch is pending)",
                          depends_on=Q_INPUTS)
        self.output_array("sliding_vector", 3, lambda: self.feedthrough(self._evaluate)[2], "rad/s",
                          "Sliding vector s = omega - omega_d + k sign(dq4) dq_1:3 (Eq. 70)",
                          depends_on=Q_INPUTS + RATE_INPUTS)

    def build_model(self):
        J = self.inertia(rigid_body.box_inertia)
        q_d0 = None if self.values["q_d_from_measured"] else self.vector("q_d0", 4)
        return deorbit_tracking.DeorbitTrackingController(
            J, self.values["k"], self.vector("G", 3), self.vector("e", 3), self.vector("omega_d", 3),
            self.vector("omega_dot_d", 3), self.vector("torque_level", 3), q_d0)

    def _evaluate(self):
        return self.model.evaluate(self.vector("q_BN", 4), self.vector("omega_BN_B", 3))

    def _command(self):
        torque, flags, _, _ = self.feedthrough(self._evaluate)
        return torque, flags

    def _done(self):
        s, e = self.feedthrough(self._evaluate)[2], self.model.e
        return all(abs(s[i]) <= e[i] for i in range(3))

    def _angle(self):
        return self.model.attitude_error(self.vector("q_BN", 4))

    def _pointing(self):
        return self.model.pointing_error(self.vector("q_BN", 4))

    def _target(self):
        return self.model.target(self.vector("q_BN", 4))

    def do_step(self, current_time, step_size):
        self.model.advance(step_size, self.vector("q_BN", 4), self.values["enabled"])
        self._input_version += 1  # q_d changed: outputs computed before the step are stale
        return True
