"""FMU `CoarseSunSensors` (instance `css`): an array of up to 8 coarse Sun sensors and the Sun
heading they give.

Wraps components.sensing.adcs_sensors.CoarseSunSensorArray (Basilisk's coarseSunSensor for each
sensor and cssWlsEst for the heading): a cosine response within each sensor's field of view,
scaled by the Sun distance and the sunlit fraction (the EarthShadow FMU's), bias, scale factor,
noise, clipped to [0, max_signal]; the heading is the (weighted) least-squares fit over the
sensors above the threshold. One noise sample per communication step, drawn in do_step; the
outputs depend directly on the inputs. Slots above css_count are unused (zero).
"""
import math

from neighbor_fmu_support import NeighborSlave

from components.core.names import matrix_names
from components.sensing import adcs_sensors

N = adcs_sensors.MAX_CSS
DEFAULT_NORMALS = adcs_sensors.six_face_normals() + [(0.0, 0.0, 1.0)] * (N - 6)


class CoarseSunSensors(NeighborSlave):
    description = ("Coarse Sun sensor array (up to 8 cosine sensors: field of view, Sun distance, shadow, bias, "
                   "scale, noise) and its least-squares Sun heading")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("css_count", 6, None, f"Number of sensors, 1..{N} (slots 1..css_count)", int)
        for i, row in enumerate(matrix_names("normal_B", N, 3)):
            for j in range(3):
                self.parameter(row[j], DEFAULT_NORMALS[i][j], "1", f"Normal of sensor {i + 1} in B, normalized "
                               f"(non-zero; component {j + 1}); default one on each face, +x -x +y -y +z -z")
        self.parameter("fov", math.radians(80.0), "rad", "Field of view half angle, in (0, pi]")
        self.parameter("scale", 1.0, "1", "Scale factor of the signals, > 0 (1: signal 1 at normal incidence, 1 AU)")
        self.parameter("bias", 0.0, "1", "Bias added to each signal before the scale factor")
        self.parameter("sigma", 0.005, "1", "White-noise standard deviation per sample per sensor, >= 0")
        self.parameter("max_signal", 0.0, "1", "Saturation of each signal, >= 0 (0: none)")
        self.parameter("threshold", 0.1, "1", "Signals above it are used for the heading, >= 0")
        self.parameter("use_weights", True, None, "Weight each sensor by its signal in the fit (else equal weights)",
                       bool)
        self.parameter("seed", 0, None, "Seed of the noise generator numpy.random.default_rng(seed), >= 0", int)
        inputs = (self.input_array("q_BN", [0.0, 0.0, 0.0, 1.0], "1", "True attitude quaternion q_BN, scalar last")
                  + self.input_array("r_BN_N", [6878137.0, 0.0, 0.0], "m", "Spacecraft position in N")
                  + self.input_array("r_SN_N", [adcs_sensors.AU, 0.0, 0.0], "m", "Sun position in N")
                  + (self.input("sunlit_fraction", 1.0, "1", "Fraction of the Sun's disc seen (EarthShadow)"),))
        out = lambda: self.feedthrough(self._output)  # noqa: E731
        self.output_array("css_signal", N, lambda: out()[0], "1", "Signal of each sensor", depends_on=inputs)
        self.output_array("sun_heading_B", 3, lambda: out()[1], "1",
                          "Unit Sun heading in B from the signals (zero when not valid)", depends_on=inputs)
        self.output("sun_valid", lambda: out()[2], None, "A heading: at least one signal above the threshold",
                    bool, depends_on=inputs)
        self.output("sensors_used", lambda: out()[3], None, "Number of signals above the threshold", int,
                    depends_on=inputs)

    def build_model(self):
        v = self.values
        count = v["css_count"]
        if not 1 <= count <= N:
            raise ValueError(f"css_count = {count} must be in 1..{N}")
        normals = [[v[e] for e in row] for row in matrix_names("normal_B", N, 3)][:count]
        return adcs_sensors.CoarseSunSensorArray(normals, v["fov"], v["scale"], v["bias"], v["sigma"], v["max_signal"],
                                                 v["threshold"], v["use_weights"], v["seed"])

    def _output(self):
        model = self.model
        signals = model.signals(self.vector("q_BN", 4), self.vector("r_BN_N", 3), self.vector("r_SN_N", 3),
                                self.input_value("sunlit_fraction"))
        heading, valid, used = model.heading(signals)
        padded = [0.0] * N
        padded[:model.count] = signals.tolist()
        return padded, heading.tolist(), valid, used

    def do_step(self, current_time, step_size):
        self.model.step(step_size)
        self._input_version += 1  # a new noise sample
        return True
