"""FMU `TrackingController` (instance `tracking`): de-orbit attitude tracking (sliding mode).

Wraps components.attitude.deorbit_tracking.DeorbitTrackingController (thesis Eq. 67-73, Appendix C
`Deorbit` and `TargetQuaternion`, Appendix F). Same thruster-controller connectors as the slew
and detumble controllers (`enabled`, `torque_cmd_B[3]`, `thrust_flag[3]`, `done`), so a system
swaps controllers by switching `enabled`; thrust time and propellant are counted by RcsThrusters.

State: the desired quaternion q_d. With q_d_from_measured (default, Appendix F `q_d = q`) it is
latched from the q_BN input at the first step while enabled (before that the outputs use
q_d = q_BN) and released while disabled; otherwise it starts at q_d0 and is propagated every
step. Each do_step propagates it at omega_d over the communication step (Eq. 19-21).
With target_from_input (appended after the thesis' variables) q_d and omega_d follow the inputs
q_target_BN and omega_target_B instead: the burn attitude the guidance computes from the actual
orbit, in place of the Eq. 67 rate at Re + 400 km; each new target re-anchors q_d, which is
propagated in between (DeorbitTrackingController.follow).
With knowledge_sigmas or impulse_bits (appended last) the boundary layer e widens with the
estimator's 1-sigma attitude error (input sigma_attitude_B) and the impulse bit, so the law does
not fire at the estimate's noise (DeorbitTrackingController.boundary_layer); 0 and 0 (the
defaults) keep the thesis' fixed e.

The inputs and outputs are values shared with the runtime, and the step and the outputs are one
compiled kernel (deorbit_tracking.tracking_into, the methods' bits); once numba is in the process
the binary calls both natively (components.attitude.native_steps.tracking_law). Every output
depends on inputs: the step leaves them stale, and the get after the master's sets publishes them.
"""
import numpy as np
from neighbor_fmu_support import TARGET_INPUTS, NeighborSlave

from components.attitude import deorbit_tracking, rigid_body, thruster_control
from components.core.names import element_names

SIGMA_INPUTS = element_names("sigma_attitude_B", 3)


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
        reads = lambda s: s.q_BN + s.omega_BN_B + TARGET_INPUTS + SIGMA_INPUTS  # noqa: E731
        ctl = self.thruster_controller_interface(
            self._command, self._done, reads, reads,
            "Tracking converged: every sliding-vector component within its threshold e (the burn itself "
            "ends on the propellant budget, not on this signal)")
        self.output("attitude_error", lambda: self.feedthrough(self._angle), "rad",
                    "Rotation angle from the desired to the current attitude, 2 acos|dq4|",
                    depends_on=ctl.q_BN + TARGET_INPUTS)
        self.output("pointing_error", lambda: self.feedthrough(self._pointing), "rad",
                    "Angle between the body x axis (de-orbit thrust axis) and the desired x axis",
                    depends_on=ctl.q_BN + TARGET_INPUTS)
        self.output_array("q_d", 4, lambda: self.feedthrough(self._target), "1",
                          "Desired quaternion q_BN, scalar last (equals q_BN while the latch is pending)",
                          depends_on=ctl.q_BN + TARGET_INPUTS)
        self.output_array("sliding_vector", 3, lambda: self.feedthrough(self._evaluate)[2], "rad/s",
                          "Sliding vector s = omega - omega_d + k sign(dq4) dq_1:3 (Eq. 70)",
                          depends_on=reads(ctl))
        self.parameter("target_from_input", False, None,
                       "True: q_d and omega_d are the inputs q_target_BN and omega_target_B (burn guidance from the "
                       "actual orbit); false: the thesis' q_d propagated at the parameter omega_d", bool)
        self.target_inputs("used when target_from_input")
        self.parameter("knowledge_sigmas", 0.0, "1",
                       "Boundary layer sized for estimates: the law's deadband in s at least this many sigmas of "
                       "the estimate's noise (0: off, the thesis' fixed e; >= 0)")
        self.parameter("impulse_bits", 0.0, "1",
                       "Boundary layer: the law's deadband in s at least this many impulse bits (0: off; >= 0)")
        self.parameter("rate_sigma", 0.0, "rad/s", "1-sigma error of the rate estimate per axis (>= 0)")
        self.parameter("min_on_time", 0.015, "s", "Shortest firing, for the impulse bit (> 0; the attitude step)")
        self.input_array("sigma_attitude_B", [0.0] * 3, "rad",
                         "1-sigma attitude error of the estimate about the body axes (from the estimator; 0: "
                         "perfect knowledge)")
        self.output_array("boundary_layer", 3, lambda: self.feedthrough(self._layer), "rad/s",
                          "The saturation thresholds e in use (the fixed e, or wider for the estimate's noise and "
                          "the impulse bit)", depends_on=SIGMA_INPUTS)
        self.share_values()
        self._inputs_at = self.shared_indices(deorbit_tracking.READS)
        self._outputs_at = self.shared_indices(deorbit_tracking.PUBLISHED)

    def build_model(self):
        J = self.inertia(rigid_body.box_inertia)
        q_d0 = None if self.values["q_d_from_measured"] else self.vector("q_d0", 4)
        return deorbit_tracking.DeorbitTrackingController(
            J, self.values["k"], self.vector("G", 3), self.vector("e", 3), self.vector("omega_d", 3),
            self.vector("omega_dot_d", 3), self.vector("torque_level", 3), q_d0,
            knowledge_sigmas=self.values["knowledge_sigmas"], impulse_bits=self.values["impulse_bits"],
            rate_sigma=self.values["rate_sigma"], min_on_time=self.values["min_on_time"])

    def _targeted(self):
        """The model, its reference taken from the inputs when target_from_input and enabled (a
        disabled controller's inputs are not refreshed by a master that suspends it)."""
        if self.values["target_from_input"] and self.input_value("enabled"):
            self.model.follow(self.vector("q_target_BN", 4), self.vector("omega_target_B", 3))
        return self.model

    def _layer(self):
        return self.model.boundary_layer(self.vector("sigma_attitude_B", 3))

    def _evaluate(self):
        self.feedthrough(self._layer)  # e for these inputs, before the law uses it
        return self._targeted().evaluate(self.vector("q_BN", 4), self.vector("omega_BN_B", 3))

    def _command(self):
        torque, flags, _, _ = self.feedthrough(self._evaluate)
        return torque, flags

    def _done(self):
        s, e = self.feedthrough(self._evaluate)[2], self.feedthrough(self._layer)
        return all(abs(s[i]) <= e[i] for i in range(3))

    def _angle(self):
        return self._targeted().attitude_error(self.vector("q_BN", 4))

    def _pointing(self):
        return self._targeted().pointing_error(self.vector("q_BN", 4))

    def _target(self):
        return self._targeted().target(self.vector("q_BN", 4))

    def do_step(self, current_time, step_size):
        # follow a new target (it re-anchors q_d before it is propagated) and advance, compiled; the
        # outputs are published when read (they all depend on inputs, which the master sets next)
        if self._law(step_size, True):  # a target it refuses, unchanged: the Python step raises the error
            self._targeted()
            self.model.advance(step_size, self.vector("q_BN", 4), self.input_value("enabled"))
        self._input_version += 1  # q_d changed: outputs computed before the step are stale
        self._outputs_stale()
        if not self.share_native[0] and self.native_ready():
            from components.attitude import native_steps  # numba is loaded: the same step, no Python
            model = self.model
            self.arm_native(native_steps.step("tracking_law"), model.constants, model.x, self.shared,
                            self._inputs_at, self._outputs_at, self.share_flags,
                            np.array([float(self.values["target_from_input"])]),
                            publish=native_steps.step("tracking_law_publish"))
        return True

    def publish(self):
        # the getters' values in one compiled call; where it refuses (a target or sigma that is not
        # allowed, a zero quaternion), the getters themselves, which raise the error
        if self._law(0.0, False):
            super().publish()
        else:
            self.mark_published()

    def _law(self, step_size, stepping):
        model = self.model
        return deorbit_tracking.tracking_into(model.constants, model.x, self.shared, self._inputs_at,
                                              self._outputs_at, step_size, stepping,
                                              self.values["target_from_input"])
