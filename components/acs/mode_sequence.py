"""The mode sequence of a wheel-and-coil CubeSat after separation: B-dot detumble with the coils,
then Sun-safe pointing with the wheels, then the mission's pointing mode (nadir by default), with
momentum dumping through the coils outside detumble.

Modes (the `mode` output of the AdcsModeSequence FMU):
  0 DETUMBLE  the B-dot law drives the coils; the wheels' controller is off;
  1 SUN_SAFE  the wheels point sun_axis_B at the measured Sun heading (PointingGuidance mode 3);
              the coils dump the wheels' momentum;
  2 POINTING  the wheels fly the mission's pointing mode (PointingGuidance mode `pointing_mode`,
              1 nadir by default) on the attitude estimate; the coils dump.

Transitions, each once its condition has held for `hold_time` seconds of simulation (a gyro's
noise does not flip the mode):
  DETUMBLE -> SUN_SAFE   |omega| < detumble_exit_rate;
  SUN_SAFE -> POINTING   the Sun is seen within sun_safe_exit_angle of sun_axis_B and the
                         attitude estimate is valid;
  POINTING -> SUN_SAFE   the attitude estimate is not valid;
  any      -> DETUMBLE   |omega| > detumble_entry_rate (0: never), at once: a rate the wheels
                         cannot hold (the flight software's rate alarm).
|omega| is the measured body rate (a gyro). detumble_entry_rate > detumble_exit_rate keeps a
hysteresis. The mode is a state: step() takes the inputs of the step's start and decides the mode
of the next step (a flight computer's sample-then-command cycle), so the enable flags and the
guidance mode the other laws read never depend on this step's inputs.

The coil command is the active law's: the B-dot dipole in DETUMBLE, the dumping dipole otherwise
(select_dipole). The laws themselves see their `enabled` flags (enables()).
"""
import math

import numpy as np

from ..attitude import pointing
from ..core.checks import finite_vector, non_negative

DETUMBLE, SUN_SAFE, POINTING = range(3)
MODE_NAMES = ("detumble", "sun-safe", "pointing")
TIME_TOL = 1e-9  # s: a hold accumulated from floating-point steps reaches hold_time


class ModeSequence:
    def __init__(self, detumble_exit_rate=math.radians(0.5), detumble_entry_rate=math.radians(5.0),
                 sun_safe_exit_angle=math.radians(10.0), hold_time=60.0, sun_axis_B=(0.0, 0.0, 1.0),
                 pointing_mode=pointing.NADIR, initial_mode=DETUMBLE):
        self.exit_rate = non_negative("detumble_exit_rate", detumble_exit_rate, "rad/s")
        self.entry_rate = non_negative("detumble_entry_rate", detumble_entry_rate, "rad/s")
        if self.entry_rate and not self.entry_rate > self.exit_rate:
            raise ValueError(f"detumble_entry_rate = {detumble_entry_rate!r} rad/s must be 0 (no rate alarm) or above "
                             f"detumble_exit_rate = {detumble_exit_rate!r} rad/s (the hysteresis)")
        angle = float(sun_safe_exit_angle)
        if not 0.0 < angle <= math.pi:
            raise ValueError(f"sun_safe_exit_angle = {sun_safe_exit_angle!r} rad must be in (0, pi]")
        self.cos_exit_angle = math.cos(angle)
        self.hold_time = non_negative("hold_time", hold_time, "s")
        axis = np.array(finite_vector(sun_axis_B, 3, "sun_axis_B"))
        if not np.linalg.norm(axis) > 0.0:
            raise ValueError("sun_axis_B must not be zero")
        self.sun_axis_B = axis / np.linalg.norm(axis)
        if pointing_mode not in (pointing.INERTIAL, pointing.NADIR, pointing.VELOCITY, pointing.TARGET):
            raise ValueError(f"pointing_mode = {pointing_mode!r} must be a PointingGuidance mode on the attitude "
                             f"estimate: 0 inertial, 1 nadir, 2 velocity or 4 target")
        self.pointing_mode = int(pointing_mode)
        if initial_mode not in range(3):
            raise ValueError(f"initial_mode = {initial_mode!r} must be 0 detumble, 1 sun-safe or 2 pointing")
        self.mode = int(initial_mode)
        self.held = 0.0  # s the current mode's exit condition has held
        self.time_in_mode = 0.0
        self.transitions = 0

    @property
    def guidance_mode(self):
        """PointingGuidance's mode: Sun-safe while detumbling (its output is not used) and in SUN_SAFE."""
        return self.pointing_mode if self.mode == POINTING else pointing.SUN_SAFE

    def enables(self):
        """(detumble law enabled, wheels' attitude law and dumping enabled)."""
        return self.mode == DETUMBLE, self.mode != DETUMBLE

    def select_dipole(self, detumble_dipole_B, dumping_dipole_B):
        return np.array(detumble_dipole_B if self.mode == DETUMBLE else dumping_dipole_B, dtype=float)

    def _sun_in_cone(self, sun_B, sun_valid):
        s = np.asarray(sun_B, float)
        n = float(np.linalg.norm(s))
        return bool(sun_valid) and n > 0.0 and float(self.sun_axis_B @ s) >= self.cos_exit_angle * n

    def step(self, h, omega_meas_B, sun_B, sun_valid, attitude_valid):
        """A step of h seconds with the inputs of its start; returns the mode of the next step."""
        h = float(h)
        rate = float(np.linalg.norm(np.asarray(omega_meas_B, float)))
        self.time_in_mode += h
        if self.mode != DETUMBLE and self.entry_rate and rate > self.entry_rate:
            return self._enter(DETUMBLE)
        if self.mode == DETUMBLE:
            leave, target = rate < self.exit_rate, SUN_SAFE
        elif self.mode == SUN_SAFE:
            leave, target = self._sun_in_cone(sun_B, sun_valid) and bool(attitude_valid), POINTING
        else:
            leave, target = not attitude_valid, SUN_SAFE
        self.held = self.held + h if leave else 0.0
        if leave and self.held >= self.hold_time - TIME_TOL:
            return self._enter(target)
        return self.mode

    def _enter(self, mode):
        self.mode, self.held, self.time_in_mode = mode, 0.0, 0.0
        self.transitions += 1
        return mode

    def get_state(self):
        return {"mode": self.mode, "held": self.held, "time_in_mode": self.time_in_mode,
                "transitions": self.transitions}

    def set_state(self, state):
        self.mode = int(state["mode"])
        self.held = float(state["held"])
        self.time_in_mode = float(state["time_in_mode"])
        self.transitions = int(state["transitions"])
