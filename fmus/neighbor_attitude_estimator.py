"""FMU `AttitudeEstimator` (instance `estimator`): TRIAD to start, then a multiplicative
extended Kalman filter on the gyro with nadir and Sun vector updates (thesis 3.3.1).

Wraps components.sensing.mekf.AttitudeEstimator. The same first inputs as `AttitudeDetermination`
(the TRIAD-only estimator), so a system swaps one for the other by replacing the component.
do_step(t, h) takes the inputs as the measurements of the step's end (mekf.AttitudeEstimator.step):
it propagates the attitude with the gyro sample held from the last step and the rate with the
commanded torque, then fuses the new vectors and gyro sample. Before the first TRIAD fix it
waits (`initialized` false, q_est_BN = q0). Every output is computed in do_step (no direct
feedthrough): in a Gauss-Seidel master that steps the estimator after the rigid body and the
sensors, the outputs after the step are the estimate at t + h; in a Jacobi master, at t.

`truth_feedback` (a fidelity choice, e.g. the thesis' parameter set): the controller-facing
outputs q_est_BN, omega_est_B and omega_dot_est_B are the truth inputs of the step (the filter
does not run), so controllers wired to the estimator fly on the true state.

Fault detection (appended last): with `fault_window` > 0 the mean normalized innovation squared
over that many vector updates is watched once the bias is learned; above `fault_limit` the gyro
bias is reopened and learned again (mekf.InnovationMonitor), and `bias_resets` counts it.

The fix without the Sun (appended last): with `nadir_history_time` > 0 the estimator keeps the
horizon sensor's and the gyro's samples until a fix; once they span that long and the spacecraft
has been sunlit for `sun_missing_time` with no Sun vector (every Sun sensor failed), the attitude
and the gyro bias come from the history (components/sensing/nadir_history.py; while two
attitudes fit it alike, as for a body at rest, or while its largest 1-sigma exceeds
`history_fix_sigma`, no fix: tried again after 120 s more) and
`attitude_valid` uses `valid_sigma_without_sun` until a Sun vector is seen again.
"""
import math
from operator import itemgetter

import numpy as np
from neighbor_fmu_support import NeighborSlave

from components.attitude import rigid_body
from components.core.names import element_names
from components.sensing import mekf, triad

# a step's inputs in mekf's U_* order ((name, n): n > 1 an array)
PACKED_INPUTS = (("nadir_B", 3), ("nadir_valid", 1), ("sun_B", 3), ("sun_valid", 1), ("r_BN_N", 3), ("r_SN_N", 3),
                 ("omega_meas_B", 3), ("torque_cmd_B", 3), ("coarse_sun_B", 3), ("coarse_sun_valid", 1),
                 ("q_true_BN", 4), ("omega_true_B", 3))


class AttitudeEstimator(NeighborSlave):
    description = ("Attitude estimator: TRIAD initialization from the nadir and Sun vectors, then a multiplicative "
                   "extended Kalman filter (attitude and gyro bias) with vector updates (NEIGHBOR thesis 3.3.1)")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self._out = None  # the outputs (mekf's Y_* positions), computed at the end of initialization and of each step
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
        self.output_array("omega_est_B", 3, lambda: self._outputs()[mekf.Y_RATE:mekf.Y_RATE + 3], "rad/s",
                          "Estimated angular velocity in B (the rate filter on the bias-corrected gyro; the raw "
                          "gyro before the first sample)")
        self.output_array("bias_est_B", 3, lambda: list(self.model.filter.bias), "rad/s", "Estimated gyro bias")
        self.output_array("sigma_attitude", 3, self._sigma, "rad",
                          "1-sigma attitude error about the body axes from the covariance (0 before the first fix)")
        self.output("initialized", lambda: self.values["truth_feedback"] or self.model.filter.initialized, None,
                    "The filter has started (a TRIAD fix was possible); always true with truth_feedback", bool)
        # appended after the first release's variables (their value references stay)
        self.parameter("truth_feedback", False, None,
                       "True: q_est_BN, omega_est_B and omega_dot_est_B are the truth inputs (perfect knowledge, the "
                       "filter does not run); false: the estimate", bool)
        self.parameter("update_interval", 0.0, "s",
                       "Shortest time between two updates with the same sensor, >= 0 (a vector equal to the last one "
                       "used is a held sample and never used again)")
        self.parameter("accel_sigma", 5e-4, "rad/s2",
                       "Rate filter: 1-sigma angular acceleration the torque model misses (thruster errors, "
                       "disturbances), >= 0")
        self.inertia_parameters("Spacecraft mass for the rate filter's inertia, kg (Table 2: 12 kg)")
        self.input_array("torque_cmd_B", [0.0, 0.0, 0.0], "N.m", "Torque commanded over the step just ended")
        self.input_array("q_true_BN", [0.0, 0.0, 0.0, 1.0], "1",
                         "True attitude (truth feedback, and the error outputs), scalar last")
        self.input_array("omega_true_B", [0.0, 0.0, 0.0], "rad/s", "True angular velocity in B (truth feedback)")
        self.input_array("omega_dot_true_B", [0.0, 0.0, 0.0], "rad/s2",
                         "True angular acceleration in B (truth feedback)")
        self.output_array("omega_dot_est_B", 3, lambda: self._outputs()[mekf.Y_RATE_DOT:mekf.Y_RATE_DOT + 3], "rad/s2",
                          "Estimated angular acceleration in B over the last step, from the commanded torque")
        self.output("attitude_error", lambda: self._outputs()[mekf.Y_ATTITUDE_ERROR], "rad",
                    "Angle between q_est_BN and q_true_BN after the last step (0 before the first fix)")
        self.output("rate_error", lambda: self._outputs()[mekf.Y_RATE_ERROR], "rad/s",
                    "Norm of omega_est_B - omega_true_B after the last step")
        self.parameter("use_coarse_sun", False, None,
                       "Use the coarse Sun vector (coarse_sun_B) whenever the fine Sun sensor's is not valid", bool)
        self.parameter("coarse_sun_sigma", math.radians(2.0), "rad", "Coarse Sun vector error angle RMS, >= 0")
        self.input_array("coarse_sun_B", [0.0, 0.0, 0.0], "1",
                         "Measured unit vector toward the Sun in B from coarse sun sensors (e.g. one on every face)")
        self.input("coarse_sun_valid", False, None, "Coarse Sun measurement valid", bool)
        self.parameter("valid_sigma", math.pi, "rad",
                       "attitude_valid once the filter's largest 1-sigma attitude error is at most this, > 0")
        self.output("attitude_valid", self._valid, None,
                    "The attitude is known well enough to fly on: initialized and the largest sigma_attitude at most "
                    "valid_sigma (always true with truth_feedback)", bool)
        # the filter's consistency against q_true_BN (a simulation's diagnostic; 0 with truth_feedback)
        self.output("nees", lambda: self.model.consistency.last, "1",
                    "Attitude normalized estimation error squared after the last step, dtheta^T P^-1 dtheta against "
                    "q_true_BN (chi-square, 3 degrees of freedom, when the covariance is consistent)")
        self.output("nees_mean", lambda: self.model.consistency.mean, "1",
                    "Mean attitude NEES over the steps since the first fix (3 when consistent)")
        self.output("nees_over_fraction", lambda: self.model.consistency.over_fraction, "1",
                    "Share of the steps since the first fix with the NEES above its 95 % bound 7.81 (0.05 when "
                    "consistent)")
        self.parameter("fault_window", 0, None,
                       "Fault detection: vector updates over which the mean normalized innovation squared is watched "
                       "(>= 0; 0: off)", int)
        self.parameter("fault_limit", 3.64, "1",
                       "Fault detection: the window's mean normalized innovation squared above which the gyro bias is "
                       "reopened (> 0; 3.64: probability 1e-6 for a consistent filter and a window of 100)")
        self.output("bias_resets", lambda: self.model.innovations.detections, None,
                    "Times the innovations contradicted the filter and the gyro bias was reopened (a bias jump)", int)
        self.output("innovation_largest", lambda: self.model.innovations.largest, "1",
                    "Largest window mean of the normalized innovation squared seen while watched (2 when consistent)")
        # the fix without the Sun (appended in a later release)
        self.parameter("nadir_history_time", 0.0, "s",
                       "Without a Sun vector: the span of the horizon sensor's and the gyro's history the first fix "
                       "is taken from once every Sun sensor has failed (>= 0; 0: off, the filter waits for the Sun)")
        self.parameter("sun_missing_time", 300.0, "s",
                       "Time in sunlight (the conical Earth shadow from r_BN_N and r_SN_N) with no Sun vector from any "
                       "sensor after which the Sun sensors are taken as failed (>= 0)")
        self.parameter("valid_sigma_without_sun", math.radians(1.0), "rad",
                       "valid_sigma while the filter has had no Sun vector since a fix from the history, > 0")
        self.output("fixed_without_sun", lambda: self.model.without_sun, None,
                    "The filter started from the horizon sensor's history and has had no Sun vector since", bool)
        self.parameter("history_fix_sigma", 0.0, "rad",
                       "The history's fix is taken only once its largest 1-sigma attitude error per axis is this or "
                       "less, else tried again after 120 s more history (>= 0; 0: any)")
        # a step's inputs packed in mekf's U_* order, and its outputs (Y_*)
        self._pick_packed = itemgetter(*(e for name, n in PACKED_INPUTS
                                         for e in (element_names(name, n) if n > 1 else (name,))))
        self._packed, self._packed_out = np.zeros(mekf.U_SIZE), np.zeros(mekf.Y_SIZE)
        self.share_values(outputs=False)
        # the same inputs by their places in the shared array (values the binary wrote there)
        self._packed_at = None if self.shared is None else self.shared_indices(PACKED_INPUTS)

    def build_model(self):
        v = self.values
        if not (v["gyro_sample_time"] > 0.0):
            raise ValueError(f"gyro_sample_time = {v['gyro_sample_time']!r} s must be > 0")
        for name in ("valid_sigma", "valid_sigma_without_sun"):
            if not (v[name] > 0.0):
                raise ValueError(f"{name} = {v[name]!r} rad must be > 0")
        sigma_v = v["gyro_sigma"] * math.sqrt(v["gyro_sample_time"])  # rad/s^0.5
        return mekf.AttitudeEstimator(v["nadir_sigma"], v["sun_sigma"], sigma_v, v["bias_walk"], v["sigma_bias0"],
                                      v["min_separation"], inertia=self.inertia(rigid_body.box_inertia),
                                      accel_sigma=v["accel_sigma"], update_interval=v["update_interval"],
                                      coarse_sun_sigma=v["coarse_sun_sigma"] if v["use_coarse_sun"] else None,
                                      fault_window=v["fault_window"], fault_limit=v["fault_limit"],
                                      nadir_history_time=v["nadir_history_time"],
                                      sun_missing_time=v["sun_missing_time"],
                                      history_fix_sigma=v["history_fix_sigma"])

    def _q(self):
        return self._outputs()[mekf.Y_Q:mekf.Y_Q + 4]

    def _outputs(self):
        # before the end of initialization: from the values as they stand (not kept)
        return self._compute() if self._out is None else self._out

    def _valid(self):
        v = self.values
        limit = v["valid_sigma_without_sun"] if self.model.without_sun else v["valid_sigma"]
        return v["truth_feedback"] or (self.model.filter.initialized and max(self._sigma()) <= limit)

    def _sigma(self):
        f = self.model.filter
        return list(f.attitude_sigma()) if f.initialized else [0.0, 0.0, 0.0]

    def _refresh(self):
        self._out = self._compute()

    def _compute(self):
        """The outputs after a step (or at the end of initialization), from the model or the truth."""
        model, truth = self.model, self.values["truth_feedback"]
        q_true, w_true = self.vector("q_true_BN", 4), self.vector("omega_true_B", 3)
        if truth:
            q, w, w_dot = q_true, w_true, self.vector("omega_dot_true_B", 3)
        else:
            f = model.filter
            q = list(f.q) if f.initialized else self.vector("q0", 4)
            w = list(model.rate) if model.rate is not None else self.vector("omega_meas_B", 3)
            w_dot = list(model.acceleration)
        error = 0.0
        if not truth and model.filter.initialized:
            error = triad.error_angle(q, q_true)
        return [*q, *w, *w_dot, error, math.sqrt(sum((a - b) ** 2 for a, b in zip(w, w_true)))]

    def exit_initialization_mode(self):
        super().exit_initialization_mode()
        self._refresh()

    def do_step(self, current_time, step_size):
        if self.values["truth_feedback"]:
            self._refresh()
            return True
        model, u = self.model, self._packed
        u[:] = self._pick_packed(self.values) if self._packed_at is None else self.shared[self._packed_at]
        # the step, the NEES against q_true_BN and the outputs, compiled between vector updates
        if model.step_packed(u, step_size, True, self._packed_out) == 0:
            self._out = self._packed_out.tolist()
        else:  # before the first fix, or a NEES the compiled code leaves to check()
            model.check(self.vector("q_true_BN", 4))
            self._refresh()
        return True

    def _set_fmu_state(self, state):
        super()._set_fmu_state(state)
        self._refresh()
