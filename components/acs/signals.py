"""State values of the mode manager of the ACS mode specification computed from the truth (a stand-in for the
sensors and the attitude/momentum estimator of the real ACS), plus a ground-command window.

Definitions (all in B; H_B = J omega is the body's momentum, h_w the wheels' relative momentum):
- H = H_B + h_w, the total angular momentum;
- xz_momentum_error = sqrt(H_x^2 + H_z^2) (N.m.s): the momentum off the Y (spin) axis;
- momentum_error = |H - H_d| with H_d = Iy w_s y_hat (N.m.s), w_s = 5 deg/s, the specification's spin:
  the desired momentum is the body spinning at +5 deg/s about Y, or, after Deploy Wheel, the
  same momentum carried by the wheel;
- with s = sun_heading_B / |sun_heading_B|: sin_sun_elevation = s_y (elevation from the body
  X-Z plane, positive towards +Y: Reorient drives it to zero); sin_sun_azimuth = s_x /
  sqrt(s_x^2 + s_z^2) (azimuth about Y measured from +Z towards +X: Acquire drives it to zero,
  +Z at the Sun); 0 when the Sun is along +-Y (azimuth undefined);
- body_rate = |omega_BN_B| (rad/s);
- ground_command: true at communication points t with command_start <= t < command_end (a
  scripted uplink window; command_end <= command_start: never).
"""
import math

from ..core.checks import finite_parameters

PARAMETER_DEFAULTS = {"Iy": 0.13, "spin_rate": math.radians(5.0), "command_start": -1.0, "command_end": -1.0}


def check_parameters(params=None):
    p = finite_parameters(PARAMETER_DEFAULTS, params)
    for k, v in p.items():
        if k in ("Iy", "spin_rate") and v <= 0:
            raise ValueError(f"parameter {k} = {v!r} must be in (0, inf)")
    return p


class AcsSignals:
    def __init__(self, params=None, t0=0.0):
        self.p = check_parameters(params)
        self.t = float(t0)

    def values(self, H_B, h_w, omega, sun):
        """dict of the state values from the current inputs."""
        H = (H_B[0] + h_w[0], H_B[1] + h_w[1], H_B[2] + h_w[2])
        hd = self.p["Iy"] * self.p["spin_rate"]
        sn = math.sqrt(sun[0] ** 2 + sun[1] ** 2 + sun[2] ** 2)
        if sn > 0:
            s = (sun[0] / sn, sun[1] / sn, sun[2] / sn)
        else:
            s = (0.0, 0.0, 0.0)
        rxz = math.hypot(s[0], s[2])
        return {
            "xz_momentum_error": math.hypot(H[0], H[2]),
            "momentum_error": math.sqrt(H[0] ** 2 + (H[1] - hd) ** 2 + H[2] ** 2),
            "sin_sun_elevation": max(-1.0, min(1.0, s[1])),
            "sin_sun_azimuth": s[0] / rxz if rxz > 1e-12 else 0.0,
            "body_rate": math.sqrt(omega[0] ** 2 + omega[1] ** 2 + omega[2] ** 2),
        }

    @property
    def ground_command(self):
        return self.p["command_start"] <= self.t < self.p["command_end"]

    def step(self, h):
        self.t += h

    def get_state(self):
        return {"t": self.t}

    def set_state(self, state):
        self.t = float(state["t"])
