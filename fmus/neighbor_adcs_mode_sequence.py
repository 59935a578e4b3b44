"""FMU `AdcsModeSequence` (instance `modes`): the mode sequence of a wheel-and-coil CubeSat, B-dot
detumble, then Sun-safe, then the mission's pointing mode, and the coil command of the active law.

Wraps components.acs.mode_sequence.ModeSequence. The mode is a state that do_step decides from
the inputs of the step's start (gyro rate, Sun heading, the estimator's validity), so `mode`,
`guidance_mode` and the enable flags depend on no input: BdotDetumble.enabled <- detumble_enabled,
MrpFeedback.enabled and MomentumDumping.enabled <- pointing_enabled, PointingGuidance.mode <-
guidance_mode. dipole_cmd_B selects the B-dot law's dipole in detumble, the dumping law's
otherwise (wire it to TorqueCoils); in a Gauss-Seidel order put this FMU after both laws.
"""
import math

from neighbor_fmu_support import NeighborSlave

from components.acs import mode_sequence
from components.attitude import pointing


class AdcsModeSequence(NeighborSlave):
    description = ("ADCS mode sequence of a wheel-and-coil CubeSat: B-dot detumble, Sun-safe, then pointing "
                   "(nadir by default), with the coil command of the active law")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("detumble_exit_rate", math.radians(0.5), "rad/s",
                       "Detumble ends once the measured rate stays below it for hold_time, >= 0")
        self.parameter("detumble_entry_rate", math.radians(5.0), "rad/s",
                       "Back to detumble from any mode above it, > detumble_exit_rate (0: never)")
        self.parameter("sun_safe_exit_angle", math.radians(10.0), "rad",
                       "Sun-safe ends once the Sun stays within it of sun_axis_B (with a valid attitude "
                       "estimate) for hold_time, in (0, pi]")
        self.parameter("hold_time", 60.0, "s", "Time a transition's condition must hold, >= 0")
        self.parameter_array("sun_axis_B", [0.0, 0.0, 1.0], "1",
                             "Body axis Sun-safe points at the Sun (PointingGuidance's sun_axis_B)")
        self.parameter("pointing_mode", pointing.NADIR, None,
                       "PointingGuidance mode after Sun-safe: 0 inertial, 1 nadir, 2 velocity, 4 target", int)
        self.parameter("initial_mode", mode_sequence.DETUMBLE, None,
                       "Mode at the start: 0 detumble, 1 Sun-safe, 2 pointing", int)
        self.input_array("omega_meas_B", [0.0, 0.0, 0.0], "rad/s", "Measured body rate in B (gyro)")
        self.input_array("sun_heading_B", [0.0, 0.0, 0.0], "1", "Measured Sun heading in B (coarse Sun sensors)")
        self.input("sun_valid", False, None, "The Sun heading is valid", bool)
        self.input("attitude_valid", False, None, "The attitude estimate is valid (AttitudeEstimator)", bool)
        detumble = self.input_array("detumble_dipole_B", [0.0, 0.0, 0.0], "A.m2", "BdotDetumble's dipole_cmd_B")
        dumping = self.input_array("dumping_dipole_B", [0.0, 0.0, 0.0], "A.m2", "MomentumDumping's dipole_cmd_B")
        self.output("mode", lambda: self.model.mode, None, "Mode: 0 detumble, 1 Sun-safe, 2 pointing", int)
        self.output("guidance_mode", lambda: self.model.guidance_mode, None,
                    "PointingGuidance's mode: 3 Sun-safe (also while detumbling), then pointing_mode", int)
        self.output("detumble_enabled", lambda: self.model.enables()[0], None,
                    "The B-dot law is active (BdotDetumble.enabled)", bool)
        self.output("pointing_enabled", lambda: self.model.enables()[1], None,
                    "The wheels' attitude law and dumping are active (MrpFeedback.enabled, MomentumDumping.enabled)",
                    bool)
        self.output_array("dipole_cmd_B", 3, lambda: self.feedthrough(self._dipole), "A.m2",
                          "Coil dipole command of the active law (TorqueCoils' dipole_cmd_B)",
                          depends_on=detumble + dumping)
        self.output("time_in_mode", lambda: self.model.time_in_mode, "s", "Time since the mode was entered")
        self.output("transitions", lambda: self.model.transitions, None, "Mode changes so far", int)

    def build_model(self):
        v = self.values
        return mode_sequence.ModeSequence(v["detumble_exit_rate"], v["detumble_entry_rate"], v["sun_safe_exit_angle"],
                                          v["hold_time"], self.vector("sun_axis_B", 3), v["pointing_mode"],
                                          v["initial_mode"])

    def _dipole(self):
        dipole = self.model.select_dipole(self.vector("detumble_dipole_B", 3), self.vector("dumping_dipole_B", 3))
        return dipole.tolist()

    def do_step(self, current_time, step_size):
        self.model.step(step_size, self.vector("omega_meas_B", 3), self.vector("sun_heading_B", 3),
                        self.values["sun_valid"], self.values["attitude_valid"])
        self._input_version += 1  # the mode may have changed the selection
        return True
