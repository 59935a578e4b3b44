"""FMU `HorizonSensor` (instance `horizon`): nadir vector in B with seeded noise.

Wraps components.sensing.sensors.HorizonSensor (thesis 3.3.1). The noise sample is drawn once per
communication step in do_step; outputs are the current inputs' nadir direction perturbed by
the current sample (direct feedthrough of r_BN_N and q_BN). The generator state is part of
the FMU state.
"""
import math

from neighbor_fmu_support import NeighborSlave

from components.sensing import sensors


class HorizonSensor(NeighborSlave):
    description = ("Horizon sensor: unit nadir vector in the body frame, perturbed by a random rotation of "
                   "angle ~ N(0, sigma) about a random perpendicular axis (NEIGHBOR thesis 3.3.1)")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("sigma", math.radians(0.25), "rad",
                       "RMS error angle of the nadir vector (>= 0; 0.25 deg default, CubeSat IR horizon sensor class)")
        self.parameter("seed", 0, None, "Seed of the noise generator numpy.random.default_rng(seed), >= 0", int)
        position = self.input_array("r_BN_N", [6798137.0, 0.0, 0.0], "m", "Spacecraft position in N")
        quaternion = self.input_array("q_BN", [0.0, 0.0, 0.0, 1.0], "1", "True attitude quaternion q_BN, scalar last")
        self.output_array("nadir_B", 3, lambda: self.feedthrough(self._measure)[0], "1",
                          "Measured unit vector toward Earth's centre in B (zeros when invalid)",
                          depends_on=position + quaternion)
        self.output("valid", lambda: self.feedthrough(self._measure)[1], None,
                    "Nadir measurement valid (false only for a zero position)", bool, depends_on=position)
        self.share_values()
        self._outputs_at = self.shared_slice((("nadir_B", 3), ("valid", 1)))

    def build_model(self):
        return sensors.HorizonSensor(self.values["sigma"], self.values["seed"])

    def _measure(self):
        return self.model.measure(self.vector("r_BN_N", 3), self.vector("q_BN", 4))

    def do_step(self, current_time, step_size):
        self.model.step(step_size)
        self.publish_after_step()  # the new noise sample
        return True

    def publish(self):
        # the getters' values (NeighborSlave.publish) in one write
        nadir, valid = self._measure()
        self.shared[self._outputs_at] = (*nadir, valid)
        self.mark_published()
