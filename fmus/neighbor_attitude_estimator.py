"""FMU `AttitudeEstimator` (instance `estimator`): TRIAD to start, then a multiplicative
extended Kalman filter on the gyro with nadir and Sun vector updates (thesis 3.3.1).

Wraps components.sensing.mekf.AttitudeEstimator. The same inputs as `AttitudeDetermination`
(the TRIAD-only estimator), so a system swaps one for the other by replacing the component.
do_step: before the first TRIAD fix it waits (`initialized` false, q_est_BN = q0); the fix
starts the filter; afterwards each valid vector at the step's start updates it and the gyro
propagates it to the step's end, where the outputs are (state outputs; `omega_est_B`, the
bias-corrected gyro rate, is direct feedthrough).
"""
import math

from neighbor_fmu_support import NeighborSlave

from components.sensing import mekf

RATE = [f"omega_meas_B[{i}]" for i in (1, 2, 3)]


class AttitudeEstimator(NeighborSlave):
    description = ("Attitude estimator: TRIAD initialization from the nadir and Sun vectors, then a multiplicative "
                   "extended Kalman filter (attitude and gyro bias) with vector updates (NEIGHBOR thesis 3.3.1)")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("nadir_sigma", math.radians(0.25), "rad", "Horizon sensor error angle RMS, >= 0")
        self.parameter("sun_sigma", math.radians(0.5) / 3.0, "rad", "Sun sensor error angle RMS, >= 0")
        self.parameter("gyro_sigma", 5.5e-4, "rad/s", "Gyro rate noise RMS per sample, >= 0")
        self.parameter("gyro_sample_time", 0.1, "s",
                       "Gyro sample time, > 0 (angle random walk sigma_v = gyro_sigma sqrt(gyro_sample_time))")
        self.parameter("bias_walk", 1e-6, "rad/s",
                       "Gyro bias random walk: 1-sigma change of each bias component in one second, >= 0")
        self.parameter("sigma_bias0", 1e-3, "rad/s", "Initial 1-sigma uncertainty of each gyro bias component, > 0")
        self.parameter("min_separation", math.radians(5.0), "rad",
                       "Smallest angle between nadir and Sun for the initial TRIAD fix, [0, pi/2)")
        self.parameter_array("q0", [0.0, 0.0, 0.0, 1.0], "1",
                             "Output q_est_BN before the first fix (unit, scalar last)")
        self.attitude_measurement_inputs()
        self.output_array("q_est_BN", 4, self._q, "1", "Estimated attitude quaternion q_BN, scalar last")
        self.output_array("omega_est_B", 3, lambda: self.feedthrough(self._rate), "rad/s",
                          "Estimated angular velocity in B: the gyro rate less the estimated bias", depends_on=RATE)
        self.output_array("bias_est_B", 3, lambda: list(self.model.filter.bias), "rad/s", "Estimated gyro bias")
        self.output_array("sigma_attitude", 3, self._sigma, "rad",
                          "1-sigma attitude error about the body axes from the covariance (0 before the first fix)")
        self.output("initialized", lambda: self.model.filter.initialized, None,
                    "The filter has started (a TRIAD fix was possible)", bool)

    def build_model(self):
        v = self.values
        if not (v["gyro_sample_time"] > 0.0):
            raise ValueError(f"gyro_sample_time = {v['gyro_sample_time']!r} s must be > 0")
        sigma_v = v["gyro_sigma"] * math.sqrt(v["gyro_sample_time"])  # rad/s^0.5
        return mekf.AttitudeEstimator(v["nadir_sigma"], v["sun_sigma"], sigma_v, v["bias_walk"], v["sigma_bias0"],
                                      v["min_separation"])

    def _q(self):
        f = self.model.filter
        return list(f.q) if f.initialized else self.vector("q0", 4)

    def _sigma(self):
        f = self.model.filter
        return list(f.attitude_sigma()) if f.initialized else [0.0, 0.0, 0.0]

    def _rate(self):
        return list(self.model.filter.rate(self.vector("omega_meas_B", 3)))

    def do_step(self, current_time, step_size):
        v = self.values
        measurements = (self.vector("nadir_B", 3), v["nadir_valid"], self.vector("sun_B", 3), v["sun_valid"],
                        self.vector("r_BN_N", 3), self.vector("r_SN_N", 3))
        self.model.step(measurements, self.vector("omega_meas_B", 3), step_size)
        self._input_version += 1  # the bias changed: omega_est_B computed before the step is stale
        return True
