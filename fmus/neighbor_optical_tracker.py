"""FMU `OpticalTracker` (instance `optical`): the star-tracking optical system's tracking flag.

Wraps components.acs.optical_tracker.OpticalTracker (model in its docstring): lock after
acquisition_time of low body rate (and paddles deployed), tracking = lock and (night or within
loss_time of dawn). `tracking` depends directly on orbit_day.
"""
import math

from neighbor_fmu_support import NeighborSlave

from components.acs import optical_tracker


class OpticalTracker(NeighborSlave):
    description = ("Optical star-tracking system reduced to its tracking flag: lock at low body rate after an "
                   "acquisition time, usable at night and for a short loss time after dawn")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("max_rate", math.radians(1.0), "rad/s", "Largest body rate for a lock (> 0)")
        self.parameter("acquisition_time", 30.0, "s", "Time of continuous lock conditions to acquire (>= 0)")
        self.parameter("loss_time", 5.0, "s", "Tracking kept this long after dawn (>= 0; below ODMD)")
        self.parameter("require_paddles", True, None, "Lock needs the paddles deployed", bool)
        self.input("orbit_day", False, None, "Spacecraft in daylight", bool)
        self.input("body_rate", 0.0, "rad/s", "Magnitude of the body angular velocity")
        self.input("paddles_deployed", False, None, "Paddles in state deployed", bool)
        self.output("tracking", lambda: self.model.tracking(self.values["orbit_day"]), None,
                    "Optical system in state tracking", bool, depends_on=["orbit_day"])
        self.output("locked", lambda: self.model.locked, None, "Star-pattern lock held (acquired)", bool)

    def build_model(self):
        v = self.values
        return optical_tracker.OpticalTracker(v["max_rate"], v["acquisition_time"], v["loss_time"],
                                              v["require_paddles"])

    def do_step(self, current_time, step_size):
        v = self.values
        self.model.step(v["orbit_day"], v["body_rate"], v["paddles_deployed"], step_size)
        return True
