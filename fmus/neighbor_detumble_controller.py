"""FMU `DetumbleController` (instance `detumble`): PD rate damping with thruster thresholds.

Wraps components.attitude.detumble.DetumbleController (thesis Eq. 9-16, Appendix C `Detumble`,
stop test of Appendix D). State: the time the stop test has held (settle_time, a flight option
appended after the thesis' variables); the command is a function of the current inputs.
"""
import math

from neighbor_fmu_support import NeighborSlave

from components.attitude import detumble, thruster_control


class DetumbleController(NeighborSlave):
    description = ("Detumble controller: PD on body rates quantized to RCS thruster-pair torques (NEIGHBOR thesis "
                   "Eq. 9-16); done when the rates are within tolerance (Appendix D)")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter_array("Kp", [100.0] * 3, "N.m.s", "Proportional gain on the rate error (Eq. 32)")
        self.parameter_array("Kd", [1.0] * 3, "N.m.s2", "Derivative gain on the angular acceleration (Eq. 33)")
        self.parameter_array("omega_d", [0.0] * 3, "rad/s", "Desired angular velocity (Eq. 8)")
        self.parameter_array("omega_tol", [math.radians(0.01)] * 3, "rad/s",
                             "Rate tolerance: no firing inside it, done when all rates are inside it (> 0)")
        self.parameter_array("torque_level", thruster_control.pair_torques(), "N.m",
                             "Torque of one thruster pair per axis (Eq. 16, > 0)")
        self.parameter("signed_stop_test", False, None,
                       "False: done when |omega - omega_d| <= tol on every axis; true: Appendix D's literal one-sided "
                       "test omega - omega_d <= tol (the thesis cases)",
                       bool)
        self.thruster_controller_interface(
            self._command, self._done, lambda s: s.omega_BN_B + s.omega_dot_BN_B, lambda s: s.omega_BN_B,
            "Detumble complete: rates within tolerance (Appendix D stop test), for settle_time when it is > 0")
        self.parameter("settle_time", 0.0, "s",
                       "Settle criterion: done once the rates have stayed within omega_tol for this long (>= 0); "
                       "0: the thesis' single-sample test")
        self.target_inputs("not used by the detumble law (rates to omega_d only)")
        self.share_values()
        self._inputs_at = self.shared_indices(detumble.READS)
        self._outputs_at = self.shared_indices(detumble.PUBLISHED)

    def build_model(self):
        return detumble.DetumbleController(self.vector("Kp", 3), self.vector("Kd", 3), self.vector("omega_d", 3),
                                           self.vector("omega_tol", 3), self.vector("torque_level", 3),
                                           self.values["signed_stop_test"], self.values["settle_time"])

    def _command(self):
        return self.model.command(self.vector("omega_BN_B", 3), self.vector("omega_dot_BN_B", 3))

    def _done(self):
        return self.model.done(self.vector("omega_BN_B", 3))

    def do_step(self, current_time, step_size):
        # advance (the settle count) and publish in one compiled call: `done` follows the new count
        self.model.step_into(self.shared, self._inputs_at, self._outputs_at, step_size)
        self.mark_published()
        if not self.share_native[0] and self.native_ready():
            from components.attitude import native_steps  # numba is loaded: the same step, no Python
            model = self.model
            self.arm_native(native_steps.step("detumble_law"), model.constants, self.shared, self._inputs_at,
                            self._outputs_at, self.share_flags, model.settle.cell,
                            publish=native_steps.step("detumble_law_publish"))
        return True

    def publish(self):
        # the getters' values (NeighborSlave.publish: the gated command and the stop test)
        self.model.step_into(self.shared, self._inputs_at, self._outputs_at, 0.0, stepping=False)
        self.mark_published()
