"""FMU `SunSensor` (instance `sun_sensor`): Sun vector in B with seeded noise, field of view
and eclipse.

Wraps components.sensing.sensors.SunSensor (thesis 3.3.1, Solar MEMS nanoSSOC-D60 [43]). The noise
sample is drawn once per communication step in do_step; outputs depend directly on the
inputs. The generator state is part of the FMU state. A fault (appended last): with `failed` the
sensor gives no valid sample once it has operated `fail_time` seconds (the sum of its steps).
"""
import math

from neighbor_fmu_support import NeighborSlave

from components.sensing import sensors


class SunSensor(NeighborSlave):
    description = ("Digital sun sensor: unit Sun vector in the body frame with a random error rotation of angle "
                   "~ N(0, sigma); valid when sunlit and inside the field of view (NEIGHBOR thesis 3.3.1)")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter_array("boresight_B", [1.0, 0.0, 0.0], "1", "Sensor boresight direction in B (non-zero)")
        self.parameter("half_fov", math.radians(60.0), "rad",
                       "Half-angle of the conical field of view, (0, pi] (nanoSSOC-D60: 60 deg)")
        self.parameter("sigma", math.radians(0.5) / 3.0, "rad",
                       "RMS error angle of the Sun vector, >= 0 (nanoSSOC-D60: 0.5 deg 3 sigma)")
        self.parameter("seed", 0, None, "Seed of the noise generator numpy.random.default_rng(seed), >= 0", int)
        sun = self.input_array("r_SN_N", [0.0, -1.496e11, 0.0], "m", "Sun position in N")
        position = self.input_array("r_BN_N", [6798137.0, 0.0, 0.0], "m", "Spacecraft position in N")
        quaternion = self.input_array("q_BN", [0.0, 0.0, 0.0, 1.0], "1", "True attitude quaternion q_BN, scalar last")
        sunlit = self.input("sunlit", True, None, "Spacecraft in sunlight (false in eclipse, from an eclipse model)",
                            bool)
        deps = sun + position + quaternion + (sunlit,)
        self.output_array("sun_B", 3, lambda: self.feedthrough(self._measure)[0], "1",
                          "Measured unit vector toward the Sun in B (zeros when invalid)", depends_on=deps)
        self.output("valid", lambda: self.feedthrough(self._measure)[1], None,
                    "Sun measurement valid: sunlit and the Sun inside the field of view", bool, depends_on=deps)
        self.parameter("failed", False, None,
                       "Fault: the sensor gives no valid sample from fail_time on (dead, or blinded for good)", bool)
        self.parameter("fail_time", 0.0, "s",
                       "Operating time (the sum of the sensor's steps: its powered time in the mission) of the "
                       "failure when failed (>= 0)")
        self.share_values()
        self._outputs_at = self.shared_slice((("sun_B", 3), ("valid", 1)))

    def build_model(self):
        return sensors.SunSensor(self.vector("boresight_B", 3), self.values["half_fov"], self.values["sigma"],
                                 self.values["seed"], self.values["fail_time"] if self.values["failed"] else None)

    def _measure(self):
        return self.model.measure(self.vector("r_SN_N", 3), self.vector("r_BN_N", 3), self.vector("q_BN", 4),
                                  self.input_value("sunlit"))

    def do_step(self, current_time, step_size):
        self.model.step(step_size)
        self.publish_after_step()  # the new noise sample
        return True

    def publish(self):
        # the getters' values (NeighborSlave.publish) in one write
        sun, valid = self._measure()
        self.shared[self._outputs_at] = (*sun, valid)
        self.mark_published()
