"""FMU `AcsSignals` (instance `signals`): the mode manager's state values from the truth.

Wraps components.acs.signals.AcsSignals (definitions in its docstring): a stand-in for the
sensors and estimator. The state values depend directly on the inputs; ground_command is a
scripted uplink window on the model's time (the start time at initialization, t + h after
do_step(t, h)), so it is a state.
"""
from neighbor_fmu_support import NeighborSlave

from components.acs import signals


class AcsSignals(NeighborSlave):
    description = ("State values of the ACS mode manager (ACS mode specification) from the truth (momentum "
                   "errors, Sun "
                   "elevation/azimuth sines, body rate) and a scripted ground-command window")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        d = signals.PARAMETER_DEFAULTS
        self.parameter("Iy", d["Iy"], "kg.m2", "Spacecraft inertia about Y for H_d = Iy spin_rate (> 0)")
        self.parameter("spin_rate", d["spin_rate"], "rad/s",
                       "Desired spin rate about +Y (> 0; the specification's 5 deg/s)")
        self.parameter("command_start", d["command_start"], "s", "Ground command true from this time")
        self.parameter("command_end", d["command_end"], "s",
                       "Ground command true until this time (exclusive; <= command_start: never)")
        momentum = self.input_array("H_B", [0.0, 0.0, 0.0], "N.m.s", "Body angular momentum J omega in B")
        wheel_momentum = self.input_array("wheel_momentum_B", [0.0, 0.0, 0.0], "N.m.s",
                                          "Wheel momentum relative to the body in B")
        omega = self.input_array("omega_BN_B", [0.0, 0.0, 0.0], "rad/s", "Body angular velocity in B")
        sun = self.input_array("sun_heading_B", [0.0, 0.0, 1.0], "1", "Unit vector to the Sun in B")
        f = lambda: self.feedthrough(self._values)  # noqa: E731
        self.output("xz_momentum_error", lambda: f()["xz_momentum_error"], "N.m.s",
                    "|(H_x, H_z)| of the total momentum H = H_B + wheel_momentum_B",
                    depends_on=momentum + wheel_momentum)
        self.output("momentum_error", lambda: f()["momentum_error"], "N.m.s",
                    "|H - Iy spin_rate y_hat| of the total momentum", depends_on=momentum + wheel_momentum)
        self.output("sin_sun_elevation", lambda: f()["sin_sun_elevation"], "1",
                    "Sine of the Sun elevation from the body X-Z plane (+ towards +Y)", depends_on=sun)
        self.output("sin_sun_azimuth", lambda: f()["sin_sun_azimuth"], "1",
                    "Sine of the Sun azimuth about Y from +Z towards +X", depends_on=sun)
        self.output("body_rate", lambda: f()["body_rate"], "rad/s", "|omega_BN_B|", depends_on=omega)
        self.output("ground_command", lambda: self.model.ground_command, None,
                    "Ground command received: command_start <= t < command_end", bool)

    def _values(self):
        return self.model.values(self.vector("H_B", 3), self.vector("wheel_momentum_B", 3),
                                 self.vector("omega_BN_B", 3), self.vector("sun_heading_B", 3))

    def build_model(self):
        return signals.AcsSignals({k: self.values[k] for k in signals.PARAMETER_DEFAULTS}, self.start_time)

    def do_step(self, current_time, step_size):
        self.model.step(step_size)
        return True
