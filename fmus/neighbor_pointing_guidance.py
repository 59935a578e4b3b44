"""FMU `PointingGuidance` (instance `guidance`): the reference attitude of a pointing mode and the
attitude tracking error the feedback laws take.

Wraps components.attitude.pointing.PointingGuidance (Basilisk's inertial3D, hillPoint,
velocityPoint, sunSafePoint, locationPointing and attTrackingError): `mode` 0 inertial
(sigma_R0N), 1 nadir (Hill frame: body x at zenith, z on the orbit normal; sigma_R0R offsets the
body), 2 velocity, 3 Sun-safe (sun_axis_B on the measured Sun heading, the search rate when the
Sun is not seen), 4 ground target (boresight_B on a point of the rotating Earth). Outputs
sigma_BR, omega_BR_B, omega_RN_B and domega_RN_B for MrpFeedback, the reference attitude q_RN and
the pointing error angle. Every output is direct feedthrough of the inputs the mode reads; the
target mode's error rate is a finite difference over the last step (its state).
"""
import math

from neighbor_fmu_support import NeighborSlave

from components.attitude import pointing
from components.core import mrp, time_utils
from components.core.constants import MU_EARTH, WGS84_A


class PointingGuidance(NeighborSlave):
    description = ("Pointing guidance: inertial, nadir (Hill), velocity, Sun-safe and ground-target references "
                   "and the attitude tracking error (sigma_BR, omega_BR_B, omega_RN_B, domega_RN_B) for a feedback law")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter_array("sigma_R0N", [0.0, 0.0, 0.0], "1", "Inertial mode's reference attitude (MRP of R "
                             "relative to N)")
        self.parameter_array("sigma_R0R", [0.0, 0.0, 0.0], "1", "Body offset of the reference in modes 0-2 (MRP of "
                             "the mode's frame R0 relative to the one the body tracks), e.g. [0, tan(22.5 deg), 0] "
                             "puts -z (not -x) at nadir")
        self.parameter("mu", MU_EARTH, "m3/s2", "Gravitational parameter of the velocity frame's orbit, > 0")
        self.parameter_array("sun_axis_B", [0.0, 0.0, 1.0], "1", "Sun-safe mode's body axis to the Sun (normalized)")
        self.parameter("sun_spin_rate", 0.0, "rad/s", "Sun-safe mode's spin rate about the Sun heading")
        self.parameter_array("search_rate_B", [0.0, 0.0, math.radians(0.5)], "rad/s",
                             "Sun-safe mode's body rate when the Sun is not seen")
        self.parameter("min_sun_norm", pointing.DEFAULT_MIN_SUN_NORM, "1",
                       "Sun-safe mode: a Sun heading shorter than this is not seen, > 0")
        self.parameter_array("boresight_B", [0.0, 0.0, 1.0], "1", "Target mode's body axis to the target (normalized)")
        self.parameter("target_latitude", 0.0, "rad", "Target's geodetic latitude (WGS-84), in [-pi/2, pi/2]")
        self.parameter("target_longitude", 0.0, "rad", "Target's east longitude")
        self.parameter("target_height", 0.0, "m", "Target's height above the WGS-84 ellipsoid")
        self.parameter("epoch", time_utils.DEFAULT_EPOCH, None, "Scenario epoch (simulation time 0) of the Earth's "
                       "rotation, ISO 8601 UTC 'YYYY-MM-DDThh:mm:ss[.fff]Z'", str)
        self.parameter("boresight_rate_damping", False, None, "Target mode: also damp the rate about the line of "
                       "sight", bool)
        self.parameter("small_angle", pointing.DEFAULT_SMALL_ANGLE, "rad",
                       "Sun-safe and target modes: a pointing error below it is zero, > 0")
        mode = self.input("mode", 0, None, "Pointing mode: 0 inertial, 1 nadir (Hill), 2 velocity, 3 Sun-safe, "
                          "4 ground target", int)
        attitude = self.input_array("q_BN", [0.0, 0.0, 0.0, 1.0], "1",
                                    "Attitude quaternion of B relative to N, scalar last (estimate or truth)")
        rate = self.input_array("omega_BN_B", [0.0, 0.0, 0.0], "rad/s", "Body angular velocity relative to N in B")
        position = self.input_array("r_BN_N", [WGS84_A + 500e3, 0.0, 0.0], "m", "Spacecraft position in N")
        velocity = self.input_array("v_BN_N", [0.0, 7612.0, 0.0], "m/s", "Spacecraft velocity in N")
        sun = self.input_array("sun_heading_B", [0.0, 0.0, 0.0], "1", "Measured Sun heading in B (Sun-safe mode; "
                               "a unit vector, or shorter than min_sun_norm when the Sun is not seen)")
        sun_valid = self.input("sun_valid", True, None, "The Sun heading is valid (Sun-safe mode)", bool)
        every = (mode,) + attitude + rate + position + velocity + sun + (sun_valid,)
        out = lambda: self.feedthrough(self._evaluate)  # noqa: E731
        for k, (name, unit, text) in enumerate((
                ("sigma_BR", "1", "Attitude error: MRP of B relative to the reference R (short set)"),
                ("omega_BR_B", "rad/s", "Body rate relative to the reference, in B"),
                ("omega_RN_B", "rad/s", "Reference rate relative to N, in B"),
                ("domega_RN_B", "rad/s2", "Reference angular acceleration relative to N, in B"))):
            self.output_array(name, 3, lambda k=k: out()[k].tolist(), unit, text, depends_on=every)
        self.output_array("q_RN", 4, lambda: list(mrp.to_quaternion(out()[4])), "1",
                          "Reference attitude quaternion of R relative to N, scalar last", depends_on=every)
        self.output("pointing_error", lambda: 4.0 * math.atan(float(sum(x * x for x in out()[0])) ** 0.5), "rad",
                    "Principal angle of the attitude error sigma_BR", depends_on=every)

    def build_model(self):
        v = self.values
        return pointing.PointingGuidance(
            self.vector("sigma_R0N", 3), self.vector("sigma_R0R", 3), v["mu"], self.vector("sun_axis_B", 3),
            v["sun_spin_rate"], self.vector("search_rate_B", 3), self.vector("boresight_B", 3), v["target_latitude"],
            v["target_longitude"], v["target_height"], v["epoch"], v["boresight_rate_damping"], v["small_angle"],
            v["min_sun_norm"], self.start_time)

    def _evaluate(self):
        return self.model.guidance(self.input_value("mode"), self.vector("q_BN", 4), self.vector("omega_BN_B", 3),
                                   self.vector("r_BN_N", 3), self.vector("v_BN_N", 3), self.vector("sun_heading_B", 3),
                                   self.input_value("sun_valid"))

    def do_step(self, current_time, step_size):
        self.model.step(self.input_value("mode"), self.vector("q_BN", 4), self.vector("r_BN_N", 3), step_size)
        self._input_version += 1  # the time and the target's previous error changed
        return True
