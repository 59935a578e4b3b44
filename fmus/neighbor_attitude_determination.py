"""FMU `AttitudeDetermination` (instance `ad`): TRIAD fixes from nadir and Sun vectors, gyro
propagation between fixes.

Wraps components.sensing.triad.AttitudeDetermination (thesis 3.3.1). At each communication point the
estimate is the TRIAD fix of the current inputs when both vectors are valid (direct
feedthrough), otherwise the estimate propagated with the measured rate over the last step
(state). do_step propagates the estimate at the start of the step (fix or not) with the rate
input held over the step.
"""
import math

from neighbor_fmu_support import NeighborSlave

from components.sensing import triad


class AttitudeDetermination(NeighborSlave):
    description = ("Attitude determination: TRIAD from the nadir (horizon sensor) and Sun vectors when both are "
                   "valid, otherwise the estimate propagated with the gyro rate (NEIGHBOR thesis 3.3.1)")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("nadir_sigma", math.radians(0.25), "rad",
                       "Horizon sensor error RMS, >= 0; the vector with the smaller sigma goes first in TRIAD "
                       "(nadir on a tie)")
        self.parameter("sun_sigma", math.radians(0.5) / 3.0, "rad", "Sun sensor error RMS, >= 0")
        self.parameter("min_separation", math.radians(5.0), "rad",
                       "Smallest angle between nadir and Sun for a TRIAD fix, [0, pi/2)")
        self.parameter_array("q0", [0.0, 0.0, 0.0, 1.0], "1",
                             "Initial estimate q_BN (used until the first fix; normalized, non-zero)")
        measured = self.attitude_measurement_inputs()
        self.output_array("q_est_BN", 4, lambda: self.feedthrough(self._estimate)[0], "1",
                          "Estimated attitude quaternion q_BN, scalar last", depends_on=measured.vectors)
        self.output_array("omega_est_B", 3, lambda: self.feedthrough(self._rate), "rad/s",
                          "Estimated angular velocity in B (the gyro measurement; no bias estimation)",
                          depends_on=measured.rate)
        self.output("fix", lambda: self.feedthrough(self._estimate)[1], None,
                    "The estimate at this communication point is a TRIAD fix", bool, depends_on=measured.vectors)
        self.output("time_since_fix", lambda: self.feedthrough(self._estimate)[2], "s",
                    "Time since the last TRIAD fix (since the start before the first fix)", depends_on=measured.vectors)

    def build_model(self):
        return triad.AttitudeDetermination(self.values["nadir_sigma"], self.values["sun_sigma"],
                                           self.vector("q0", 4), self.values["min_separation"])

    def _measurements(self):
        v = self.values
        return (self.vector("nadir_B", 3), v["nadir_valid"], self.vector("sun_B", 3), v["sun_valid"],
                self.vector("r_BN_N", 3), self.vector("r_SN_N", 3))

    def _estimate(self):
        return self.model.estimate(*self._measurements())

    def _rate(self):
        return self.vector("omega_meas_B", 3)

    def do_step(self, current_time, step_size):
        self.model.step(self._measurements(), self.vector("omega_meas_B", 3), step_size)
        self._input_version += 1  # the propagated state changed: recompute the outputs
        return True
