"""FMU `AcsModeManager` (instance `modes`): the ten-mode ACS mode manager of the ACS mode specification.

Wraps components.acs.modes.AcsModeManager: the specification's decision tables as data, evaluated at
each communication point with the inputs present there (do_step(t, h) decides at t; the mode
holds over [t, t + h]). Every output is state (mode, time in mode, permissions of the mode), so
no output depends directly on an input. The model keeps the time: the start time at
initialization (startup -> Wait), t + h after do_step(t, h).
"""
from neighbor_fmu_support import NeighborSlave

from components.acs import modes

PARAMETERS = (
    ("xz_momentum_error_threshold", "N.m.s", "Detumbled when the X-Z body momentum error is at or below it (> 0)"),
    ("spinup_momentum_error", "N.m.s", "Spun up when the momentum error is at or below it (> 0)"),
    ("coarse_elevation_error", "1", "Coarse Sun elevation error, as a sine (0, 1]"),
    ("coarse_azimuth_error", "1", "Coarse Sun azimuth error, as a sine (0, 1]"),
    ("fine_elevation_error", "1", "Fine Sun elevation error, as a sine (0, coarse_elevation_error]"),
    ("fine_azimuth_error", "1", "Fine Sun azimuth error, as a sine (0, coarse_azimuth_error]"),
    ("max_tumble_rate", "rad/s", "Maximum body rate in Orbit Night before falling to Spinup (> 0)"),
    ("nominal_wheel_rate", "rad/s", "Nominal momentum-wheel rate; Deploy Wheel below it, Acquire at or above (> 0)"),
    ("WMD", "s", "Wait mode delay (>= 0)"),
    ("DMD", "s", "Detumble mode delay (>= 0)"),
    ("SMD", "s", "Spinup mode delay (>= 0)"),
    ("RMD", "s", "Reorient mode delay (>= 0)"),
    ("DWMD", "s", "Deploy Wheel mode delay (>= 0)"),
    ("AMD", "s", "Acquire mode delay (>= 0)"),
    ("DPMD", "s", "Deploy Paddles mode delay (>= 0)"),
    ("ODMD", "s", "Orbit Day mode delay (>= 0)"),
    ("GCMD", "s", "Ground Command mode delay: back to Detumble after this long without a command (>= 0)"),
)

INPUTS = (
    ("xz_momentum_error", "N.m.s", "Magnitude of the body momentum error in the X-Z plane (>= 0)", float),
    ("momentum_error", "N.m.s", "Magnitude of the momentum error from the desired spin momentum (>= 0)", float),
    ("wheel_rate", "rad/s", "Momentum-wheel rate about Y (its magnitude is compared)", float),
    ("sin_sun_elevation", "1", "Sine of the Sun elevation from the body X-Z plane, Sun in body", float),
    ("sin_sun_azimuth", "1", "Sine of the Sun azimuth in the body X-Z plane from +Z, Sun in body", float),
    ("body_rate", "rad/s", "Magnitude of the body angular velocity (>= 0)", float),
    ("orbit_day", None, "Spacecraft in daylight", bool),
    ("paddles_deployed", None, "Solar paddles in state deployed", bool),
    ("optical_tracking", None, "Optical system in state tracking (star tracking)", bool),
    ("ground_command", None, "Ground control command received at this communication point", bool),
    ("reset", None, "Reset command received: back to Wait", bool),
)


class AcsModeManager(NeighborSlave):
    description = ("ACS mode manager (ACS mode specification): ten modes decided from the specification's "
                   "decision tables at each "
                   "communication point, with mode delays for hysteresis; falls back to Spinup when uncertain")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self._start_time = 0.0
        for name, unit, text in PARAMETERS:
            default = modes.PARAMETER_DEFAULTS[name]
            self.parameter(name, default, unit, f"{text}; default {default:.6g}")
        for name, unit, text, kind in INPUTS:
            self.input(name, modes.INPUT_DEFAULTS[name], unit, text, kind)
        self.output("mode", lambda: self.model.mode, None,
                    f"ACS mode ({modes.MODE_TABLE}), decided at the start of the last step", int)
        self.output("time_in_mode", lambda: self.model.time_in_mode, "s", "Time since the current mode was entered")
        self.output("coils_enabled", lambda: self.model.permissions[0], None,
                    "Magnetic torque coils may be commanded (false: zero dipole)", bool)
        self.output("wheel_enabled", lambda: self.model.permissions[1], None,
                    "Momentum wheel under control (false: zero torque)", bool)
        self.output("paddle_deploy", lambda: self.model.permissions[2], None,
                    "Solar paddle deployment may be activated", bool)
        self.output("uncertain", lambda: self.model.uncertain, None,
                    "The last decision fell back to Spinup: no table rule fired, or rules into different modes "
                    "fired together", bool)
        self.output("rule_table", lambda: -1 if self.model.rule is None else self.model.rule[0], None,
                    "Mode whose table holds the rule of the last decision (-1: uncertain fallback)", int)
        self.output("rule_column", lambda: 0 if self.model.rule is None else self.model.rule[1], None,
                    "1-based column of that rule in the specification's table (0: uncertain fallback)", int)

    def build_model(self):
        params = {name: self.values[name] for name, _, _ in PARAMETERS}
        return modes.AcsModeManager(params, self._start_time)

    def setup_experiment(self, start_time, stop_time=None, tolerance=None):
        self._start_time = float(start_time)
        self._model = None

    def do_step(self, current_time, step_size):
        inputs = {name: self.values[name] for name, _, _, _ in INPUTS}
        self.model.step(current_time, step_size, inputs)
        return True
