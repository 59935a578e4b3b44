"""Optical (star-tracking) system of the ACS mode specification, reduced to its "in-state tracking" flag.

Model (simple, documented):
- lock: the camera holds a star-pattern lock once its lock conditions have held continuously
  for acquisition_time: the body rate |omega| at or below max_rate (smearing) and, with
  require_paddles, the paddles deployed (the camera looks out past the stowed paddles). Any
  step with the conditions false drops the lock and restarts the acquisition.
- tracking = lock and (darkness or within loss_time of dawn): the lock gives a usable attitude
  only in the Earth's shadow (orbit_day false); in daylight stray sunlight spoils it, and the
  loss of track is declared loss_time after dawn (a debounce). The flag depends directly on
  orbit_day (it is true at the very communication point night falls, as the mode manager's
  Orbit Day -> Orbit Night column needs) and on the state.
Defaults: max_rate 1 deg/s (the mode manager's max tumble rate), acquisition_time 30 s (lost-in-
space star identification of small trackers: seconds to tens of seconds), loss_time 5 s (below
the specification's ODMD of 10 s: tracking must still be reported at dawn, Orbit Night -> Orbit Day col 4,
and lost before ODMD in Orbit Day, else Orbit Night col 3 takes it back to night).
"""
import math


def _check(name, v, positive=False):
    v = float(v)
    if not math.isfinite(v) or v < 0 or (positive and v == 0):
        raise ValueError(f"parameter {name} = {v!r} must be in {'(0' if positive else '[0'}, inf)")
    return v


class OpticalTracker:
    def __init__(self, max_rate=math.radians(1.0), acquisition_time=30.0, loss_time=5.0, require_paddles=True):
        self.max_rate = _check("max_rate", max_rate, True)
        self.acquisition_time = _check("acquisition_time", acquisition_time)
        self.loss_time = _check("loss_time", loss_time)
        self.require_paddles = bool(require_paddles)
        self.lock_time = 0.0  # s the lock conditions have held
        self.day_time = 0.0  # s of continuous daylight so far

    def conditions(self, body_rate, paddles_deployed):
        return body_rate <= self.max_rate and (paddles_deployed or not self.require_paddles)

    @property
    def locked(self):
        return self.lock_time >= self.acquisition_time - 1e-9

    def tracking(self, orbit_day):
        return self.locked and (not orbit_day or self.day_time < self.loss_time - 1e-9)

    def step(self, orbit_day, body_rate, paddles_deployed, h):
        self.lock_time = self.lock_time + h if self.conditions(body_rate, paddles_deployed) else 0.0
        self.day_time = self.day_time + h if orbit_day else 0.0

    def get_state(self):
        return {"lock_time": self.lock_time, "day_time": self.day_time}

    def set_state(self, state):
        self.lock_time = float(state["lock_time"])
        self.day_time = float(state["day_time"])
