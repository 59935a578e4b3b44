"""FMU `AcsControl` (instance `control`): the per-mode control laws of the ACS of the mode specification.

Wraps components.acs.control.AcsControl (the laws and their equations are in its docstring):
mode and permissions from the mode manager, body rate, field, Sun heading, wheel rate and time
in mode in; commanded coil dipole and wheel motor torque out. Stateless; both outputs are
direct feedthrough of the inputs.
"""
from neighbor_fmu_support import NeighborSlave

from components.acs import control, modes

PARAMETERS = (
    ("Ix", "kg.m2", "Spacecraft inertia about X (> 0)"),
    ("Iy", "kg.m2", "Spacecraft inertia about Y, the spin axis (> 0)"),
    ("Iz", "kg.m2", "Spacecraft inertia about Z (> 0)"),
    ("J_w", "kg.m2", "Momentum-wheel inertia about Y (> 0)"),
    ("spin_rate", "rad/s", "Desired spin rate about +Y, H_d = Iy spin_rate (> 0; the specification's 5 deg/s)"),
    ("k_detumble", "N.m.s", "Detumble gain: m_y = k (omega x B)_y / |B|^2 (> 0)"),
    ("k_nutation", "N.m.s", "Nutation damping gain of the Y coil in Spinup/Reorient (> 0)"),
    ("k_momentum", "Hz", "Momentum gain (1/s): tau_d = k (H_d - H) (> 0)"),
    ("k_precession", "Hz", "Precession gain (1/s) on the Sun's Y component in Reorient (> 0)"),
    ("k_precession_fine", "Hz", "Precession gain (1/s) on the Sun's Y component in Acquire/Orbit Day/Night (> 0)"),
    ("precession_taper", "N.m.s",
     "Momentum error below which precession has full gain, tapered to 0 at twice it (> 0)"),
    ("K_azimuth", "rad/s2", "Azimuth stiffness (1/s2 per rad) of the wheel loop (> 0)"),
    ("D_azimuth", "Hz", "Azimuth damping (1/s) of the wheel loop (> 0)"),
    ("max_slew_rate", "rad/s", "Largest body rate about Y the azimuth loop asks (> 0)"),
    ("k_wheel", "Hz", "Deploy Wheel transfer gain (1/s): tau_w = k Iy omega_y (> 0)"),
    ("reorient_hold_elevation", "1", "Sine of the Sun elevation Reorient holds until reorient_duration, [0, 1)"),
    ("reorient_duration", "s", "Time in Reorient before the elevation is driven to zero (set to RMD), >= 0"),
)


class AcsControl(NeighborSlave):
    description = ("ACS control laws per mode (ACS mode specification): magnetic dipole commands for the three "
                   "torque coils "
                   "and the torque command of the Y momentum wheel")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        for name, unit, text in PARAMETERS:
            default = control.PARAMETER_DEFAULTS[name]
            self.parameter(name, default, unit, f"{text}; default {default:.6g}")
        mode = self.input("mode", 0, None, f"ACS mode ({modes.MODE_TABLE})", int)
        coils_enabled = self.input("coils_enabled", False, None, "Coils permitted (false: zero dipole command)", bool)
        wheel_enabled = self.input("wheel_enabled", False, None, "Wheel permitted (false: zero torque command)", bool)
        time_in_mode = self.input("time_in_mode", 0.0, "s",
                                  "Time since the current mode was entered (Reorient schedule)")
        omega = self.input_array("omega_BN_B", [0.0, 0.0, 0.0], "rad/s", "Body angular velocity in B")
        field = self.input_array("B_B", [0.0, 0.0, 0.0], "T", "Geomagnetic field in B")
        sun = self.input_array("sun_heading_B", [0.0, 0.0, 1.0], "1", "Unit vector to the Sun in B")
        wheel_rate = self.input("wheel_rate", 0.0, "rad/s", "Momentum-wheel rate about +Y relative to the body")
        deps = (mode, coils_enabled, wheel_enabled, time_in_mode, wheel_rate) + omega + field + sun
        self.output_array("dipole_cmd_B", 3, lambda: self.feedthrough(self._command)[0], "A.m2",
                          "Commanded magnetic dipole in B (0 when coils_enabled is false)", depends_on=deps)
        self.output("wheel_torque_cmd", lambda: self.feedthrough(self._command)[1], "N.m",
                    "Commanded wheel motor torque about +Y (0 when wheel_enabled is false)",
                    depends_on=(mode, wheel_enabled, omega[1]) + sun)

    def _command(self):
        v = self.values
        return self.model.command(v["mode"], v["coils_enabled"], v["wheel_enabled"], self.vector("omega_BN_B", 3),
                                  self.vector("B_B", 3), self.vector("sun_heading_B", 3), v["wheel_rate"],
                                  v["time_in_mode"])

    def build_model(self):
        return control.AcsControl({name: self.values[name] for name, _, _ in PARAMETERS})

    def do_step(self, current_time, step_size):
        return True
