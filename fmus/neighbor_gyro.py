"""FMU `Gyro` (instance `gyro`): 3-axis rate gyro with bias and seeded white noise.

Wraps components.sensing.sensors.Gyro (thesis 3.3.1, Bosch BMG160 [44]). One noise sample per
communication step, drawn in do_step; the output depends directly on the true rate. A fault
(appended last): `bias_jump` added to the bias once the gyro has operated `jump_time` seconds (the
sum of its steps; zero jump: none). Once numba is in the process the binary takes the step and
publishes the output without Python (components.sensing.native_steps.gyro; the samples come from
the model's block of noise, which the Python step refills).
"""
from neighbor_fmu_support import NeighborSlave

from components.sensing import sensors

class Gyro(NeighborSlave):
    description = ("3-axis rate gyro: omega_meas = omega_BN_B + bias + N(0, sigma^2) white noise per "
                   "communication step (NEIGHBOR thesis 3.3.1)")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter_array("bias", [0.0, 0.0, 0.0], "rad/s", "Constant rate bias")
        self.parameter("sigma", 5.5e-4, "rad/s",
                       "White-noise standard deviation per sample per axis, >= 0 (BMG160 0.014 deg/s/sqrt(Hz) "
                       "over a 5 Hz bandwidth, i.e. 10 Hz sampling)")
        self.parameter("seed", 0, None, "Seed of the noise generator numpy.random.default_rng(seed), >= 0", int)
        rate = self.input_array("omega_BN_B", [0.0, 0.0, 0.0], "rad/s",
                                "True angular velocity of B relative to N, in B")
        self.output_array("omega_meas_B", 3, lambda: self.feedthrough(self._measure), "rad/s",
                          "Measured angular velocity in B", depends_on=rate)
        # appended after the first release's variables (their value references stay)
        self.parameter("sigma_sample_time", 0.0, "s",
                       "Sampling step at which sigma holds, >= 0; 0: every sample has sigma. Otherwise a sample at the "
                       "communication step h has sigma sqrt(sigma_sample_time / h) (white noise of fixed density)")
        self.parameter_array("bias_jump", [0.0, 0.0, 0.0], "rad/s",
                             "Fault: bias shift added from jump_time on (a shock or temperature step; zero: no fault)")
        self.parameter("jump_time", 0.0, "s",
                       "Operating time (the sum of the gyro's steps: its powered time in the mission) from which "
                       "bias_jump applies (>= 0)")
        self.share_values()
        self._outputs_at = self.shared_slice((("omega_meas_B", 3),))
        self._native_at = (self.shared_indices((("omega_BN_B", 3),)), self.shared_indices((("omega_meas_B", 3),)))

    def build_model(self):
        return sensors.Gyro(self.vector("bias", 3), self.values["sigma"], self.values["seed"],
                            self.values["sigma_sample_time"], self.vector("bias_jump", 3),
                            self.values["jump_time"])

    def _measure(self):
        return self.model.measure(self.vector("omega_BN_B", 3))

    def do_step(self, current_time, step_size):
        self.model.step(step_size)
        self.publish_after_step()  # the new noise sample
        if not self.share_native[0] and self.native_ready():
            from components.sensing import native_steps  # numba is loaded: the same step, no Python
            model = self.model
            self.arm_native(native_steps.step("gyro"), model.constants, model.x, model.block, self.shared,
                            *self._native_at, self.share_flags, publish=native_steps.step("gyro_publish"))
        return True

    def publish(self):
        # the getter's value (NeighborSlave.publish) in one write
        self.shared[self._outputs_at] = self._measure()
        self.mark_published()
