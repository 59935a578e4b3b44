"""FMU `Magnetometer` (instance `magnetometer`): a three-axis magnetometer with mounting, bias,
scale factor, saturation and seeded white noise.

Wraps components.sensing.adcs_sensors.Magnetometer (Basilisk's magnetometer model): the field in
B from the field FMU (MagneticField or MagneticFieldIgrf `B_B`) turned into the sensor frame by
the 3-2-1 mounting angles, plus bias and noise, times the scale factor, each axis clipped to
+-max_field. One noise sample per communication step, drawn in do_step; the output depends
directly on the field input.
"""
from neighbor_fmu_support import NeighborSlave

from components.sensing import adcs_sensors


class Magnetometer(NeighborSlave):
    description = ("Three-axis magnetometer: the field in B turned into the sensor frame (3-2-1 mounting), bias, "
                   "scale factor, saturation and white noise per communication step")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter_array("mounting_321", [0.0, 0.0, 0.0], "rad",
                             "Sensor frame from B: 3-2-1 Euler angles yaw, pitch, roll (a misalignment when small)")
        self.parameter_array("bias", [0.0, 0.0, 0.0], "T", "Constant bias per sensor axis")
        self.parameter("scale", 1.0, "1", "Scale factor (non-zero)")
        self.parameter("sigma", 5e-8, "T", "White-noise standard deviation per sample per axis, >= 0 "
                       "(50 nT: the class of CubeSat magneto-resistive magnetometers)")
        self.parameter("max_field", 0.0, "T", "Saturation of each axis, +-max_field, >= 0 (0: none)")
        self.parameter("seed", 0, None, "Seed of the noise generator numpy.random.default_rng(seed), >= 0", int)
        field = self.input_array("B_B", [0.0, 0.0, 0.0], "T", "Magnetic field in B (the field FMU's B_B)")
        self.output_array("B_meas", 3, lambda: self.feedthrough(self._measure), "T",
                          "Measured field in the sensor frame (B when mounted aligned)", depends_on=field)

    def build_model(self):
        v = self.values
        return adcs_sensors.Magnetometer(self.vector("mounting_321", 3), self.vector("bias", 3), v["scale"],
                                         v["sigma"], v["max_field"], v["seed"])

    def _measure(self):
        return self.model.measure(self.vector("B_B", 3)).tolist()

    def do_step(self, current_time, step_size):
        self.model.step(step_size)
        self._input_version += 1  # a new noise sample
        return True
