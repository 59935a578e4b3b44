"""Per-mode control laws of the ACS of the mode specification (magnetic torque coils on X, Y, Z and a momentum
wheel on Y), commanded by the mode manager (components.acs.modes).

Inputs (all in B): mode, coils_enabled / wheel_enabled (the mode manager's permissions), the body
rate omega (rad/s), the field B (T), the Sun heading s (unit vector), the wheel rate Omega
(rad/s, about +Y) and the time in mode (s). Outputs: the commanded dipole m (A.m2) and the
wheel motor torque command tau_w (N.m, on the wheel about +Y; the body feels -tau_w).

Notation: J = diag(Ix, Iy, Iz) the spacecraft inertia, J_w the wheel inertia, H = J omega +
J_w Omega y_hat the total angular momentum in B, H_d = Iy w_s y_hat the desired spin momentum
(w_s = 5 deg/s, the specification's Spinup rate), Sun elevation sin(el) = s_y (from the X-Z plane),
azimuth az = atan2(s_x, s_z) (about Y from +Z). A desired torque tau_d is produced by the coils
as m = B x tau_d / |B|^2 (then m x B = tau_d minus its component along B, which coils cannot
produce). The coils saturate per axis downstream (components.acs.magnetorquer).

Laws (mode: dipole; wheel):
- 0 Wait: m = 0; tau_w = 0 ("none of the actuators active").
- 1 Detumble: m = (0, m_y, 0), m_y = k_d (omega x B)_y / |B|^2; tau_w = 0 (holds the entry
  speed: the wheel model is frictionless, so zero torque keeps Omega exactly). The kinetic
  energy T = 1/2 omega.J omega obeys dT/dt = omega.(m x B) = -m_y (omega x B)_y (the gyroscopic
  terms do no work), so dT/dt = -k_d (omega x B)_y^2/|B|^2 <= 0 (B-dot restricted to the Y coil).
  A Y moment torques only about X and Z, so what it removes is the X/Z rate.
- 2 Spinup: X/Z moments from tau_d = k_h (H_d - H), (m_x, m_z) of B x tau_d/|B|^2; the Y moment
  damps nutation with the detumble law, m_y = k_n (omega x B)_y / |B|^2 (energy dissipation at
  constant momentum drives the spin to the major axis Y, Iy is the largest inertia); tau_w = 0.
- 3 Reorient: as Spinup plus a precession term that turns H (the spin axis) away from the Sun's
  Y component: tau_d = k_h (H_d - H) - k_p (s_y - e_ref) |H_d| s_perp with s_perp = (s_x, 0, s_z).
  Because d(s.H)/dt = s.tau for an inertial Sun, the term gives d(s.H)/dt = -k_p (s_y - e_ref)
  |H_d| |s_perp|^2: s_y goes to the reference e_ref. e_ref = sign(s_y) reorient_hold_elevation
  while time_in_mode < reorient_duration, 0 afterwards (see "Reorient schedule"); tau_w = 0.
- 4 Deploy Wheel: m = 0 (coils not permitted); tau_w = k_w Iy omega_y, saturated by the wheel:
  the body feels -tau_w about Y, so its spin omega_y decays with time constant 1/k_w while the
  wheel takes its momentum (total H conserved).
- 5 Acquire, 7 Orbit Day, 8 Orbit Night: with the momentum on the wheel the body is nearly still.
  Azimuth with the wheel: the body's angular acceleration about Y is -tau_w/Iy and az' = -omega_y
  (an inertial Sun), so tau_w = -Iy D_a (w_ref - omega_y), w_ref = sat(K_a/D_a az, +-max_slew_rate)
  gives az'' + D_a az' + K_a az = 0 below the rate limit. The limit (0.3 deg/s: Iy x 5.2e-3 =
  6.8e-4 N.m.s, 34 rad/s of wheel speed) keeps the wheel within its 628 rad/s limit while it
  carries the 567 rad/s of the spin momentum.
  Elevation and momentum with the coils: tau_d = k_h (H_d - H) - k_pf e_H |H_d| s_perp (as
  Reorient with e_ref = 0 and the gain k_pf = k_precession_fine), all three moments, where
  e_H = s.H/|H| is the Sun elevation from the plane normal to the momentum (the wheel axis the
  still body nutates about) rather than s_y: d(s.H)/dt = s.tau holds exactly for e_H, and s_y
  also carries the nutation, which a proportional feedback on it pumps (a slowly growing X/Z
  oscillation, 0.7 deg/s after 6000 s in Orbit Day with 0.2 A.m2 coils); the body's s_y
  follows e_H as -k_h H_perp damps the nutation. k_pf = 5e-3
  1/s (200 s time constant, 2.5x Reorient's): the elevation must be within the fine error (sin 2
  deg) at dusk, since Orbit Night holds only with the fine Sun errors (Orbit Night col 4);
  1e-2 1/s drove a slow nutation/elevation divergence at 5 s steps. Orbit Night uses the same law (the
  specification draws the
  attitude from the optical system at night; here the inputs are the same truth signals).
- 6 Deploy Paddles: m = 0 ("cuts all magnetic moments to zero"); tau_w = 0 (holds the speed).
- 9 Ground Command (our choice, safe): m = 0 and tau_w = 0 (wheel holds its speed) until ground
  commands or the mode manager returns to Detumble.
Precession taper (all modes with a precession term): the term is multiplied by
clamp(2 - |H - H_d| / precession_taper, 0, 1), full below precession_taper = 6e-4 N.m.s and off
at twice it: saturated coils otherwise let the momentum error in Reorient cross the 1e-3 N.m.s
spinup momentum error, which sends Reorient back to Spinup (Reorient col 4 fails: uncertain).
When coils_enabled is false m = 0; when wheel_enabled is false tau_w = 0, whatever the mode.

Reorient schedule: the draft's Reorient table holds the mode before RMD only while the Sun
elevation is beyond the coarse error (Reorient col 4); reaching it earlier matches no rule and
the mode manager falls back to Spinup. The reference e_ref therefore keeps the elevation at
reorient_hold_elevation (just outside the coarse band) until reorient_duration (set it to RMD)
and only then drives it to zero. Set reorient_hold_elevation = 0 for the plain law.

Gains (defaults for the 12 kg host, J = diag(0.05, 0.13, 0.10) kg.m2, 0.2 A.m2 coils, |B| 20-50
uT at 420 km, torques of order 0.2 A.m2 x 30 uT = 6 uN.m):
- k_d = k_n = 2e-3 N.m.s: at the 2 deg/s of a tumble (omega x B)/|B|^2 ~ 1e3 /(s T), so
  m ~ 2 A.m2 saturates the coils (bang-bang B-dot, fastest); it falls below saturation at
  ~0.2 deg/s, where a linear law avoids chattering.
- k_h = 2e-3 1/s: a momentum error of 0.011 N.m.s (the whole spin) asks 22 uN.m, saturating;
  the loop time constant 500 s is long against the 1 s step and a few x the 90 deg/orbit-quarter
  field rotation, so it averages over the field direction.
- k_p = 2e-3 1/s: at s_y = 0.5 it asks 1.1e-5 N.m, the coils' authority; precession rates of
  ~0.05 deg/s, RMD-scale reorientations as the specification's 6000 s delay implies.
- K_a = 2.5e-3 1/s2, D_a = 0.07 1/s: 0.05 rad/s natural frequency, damping 0.7, settles in
  ~120 s (within AMD + DPMD), omega_n h = 0.05 at 1 s steps; the torque 0.13 x 2.5e-3 x 1 rad
  = 0.3 mN.m is within the 1 mN.m wheel.
- k_w = 0.1 1/s: 10 s transfer time constant, limited anyway by the 1 mN.m wheel (0.011 N.m.s
  in ~11 s), well within DWMD 180 s.
"""
import math

from ..core.checks import finite_parameters
from .modes import AcsMode

(WAIT, DETUMBLE, SPINUP, REORIENT, DEPLOY_WHEEL, ACQUIRE, DEPLOY_PADDLES, ORBIT_DAY, ORBIT_NIGHT,
 GROUND_COMMAND) = AcsMode

PARAMETER_DEFAULTS = {
    "Ix": 0.05, "Iy": 0.13, "Iz": 0.10,  # kg.m2, the 12 kg 0.3 x 0.1 x 0.2 m box
    "J_w": 2.0e-5,  # kg.m2, components.acs.momentum_wheel default
    "spin_rate": math.radians(5.0),  # rad/s, the specification's +5 deg/s about Y
    "k_detumble": 2.0e-3,  # N.m.s
    "k_nutation": 2.0e-3,  # N.m.s
    "k_momentum": 2.0e-3,  # 1/s
    "k_precession": 2.0e-3,  # 1/s
    "k_precession_fine": 5.0e-3,  # 1/s, Acquire / Orbit Day / Orbit Night (body still, H on the wheel)
    "K_azimuth": 2.5e-3,  # 1/s2
    "D_azimuth": 0.07,  # 1/s
    "k_wheel": 0.1,  # 1/s
    "max_slew_rate": math.radians(0.3),  # rad/s
    "precession_taper": 6.0e-4,  # N.m.s: precession at full gain below this momentum error, off at twice it
    "reorient_hold_elevation": math.sin(math.radians(15.0)),  # 1 (a sine), above the 10 deg coarse error
    "reorient_duration": 6000.0,  # s, the specification's RMD
}
NONNEGATIVE = ("reorient_hold_elevation", "reorient_duration")
B_MIN = 1.0e-9  # T: below it the field is taken as absent (no coil command)


def check_parameters(params=None):
    p = finite_parameters(PARAMETER_DEFAULTS, params)
    for k, v in p.items():
        if k in NONNEGATIVE:
            if v < 0 or (k == "reorient_hold_elevation" and v >= 1.0):
                upper = "1)" if k.startswith("reorient_hold") else "inf)"
                raise ValueError(f"parameter {k} = {v!r} must be in [0, {upper}")
        elif v <= 0:
            raise ValueError(f"parameter {k} = {v!r} must be in (0, inf)")
    return p


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


class AcsControl:
    """Stateless: every output is a function of the current inputs."""

    def __init__(self, params=None):
        self.p = check_parameters(params)

    def total_momentum(self, omega, wheel_rate):
        p = self.p
        return (p["Ix"] * omega[0], p["Iy"] * omega[1] + p["J_w"] * wheel_rate, p["Iz"] * omega[2])

    def _coil_dipole(self, tau_d, B, b2):
        m = _cross(B, tau_d)
        return (m[0] / b2, m[1] / b2, m[2] / b2)

    def _momentum_torque(self, H, s, e_ref, kp=None, momentum_elevation=False):
        p = self.p
        hd = p["Iy"] * p["spin_rate"]
        k = p["k_momentum"]
        kp = p["k_precession"] if kp is None else kp
        tau = [k * (0.0 - H[0]), k * (hd - H[1]), k * (0.0 - H[2])]
        if s is not None:
            err = math.sqrt(H[0] * H[0] + (H[1] - hd) * (H[1] - hd) + H[2] * H[2])
            taper = min(1.0, max(0.0, 2.0 - err / p["precession_taper"]))
            hn = math.sqrt(H[0] * H[0] + H[1] * H[1] + H[2] * H[2])
            # elevation of the momentum (the spin/wheel axis the body nutates about) when asked:
            # free of the nutation, which a feedback on s_y itself pumps (position feedback on a
            # gyroscopic mode)
            e = (s[0] * H[0] + s[1] * H[1] + s[2] * H[2]) / hn if (momentum_elevation and hn > 0) else s[1]
            g = taper * kp * (e - e_ref) * hd
            tau[0] -= g * s[0]
            tau[2] -= g * s[2]
        return tau

    def command(self, mode, coils_enabled, wheel_enabled, omega, B, sun, wheel_rate, time_in_mode=0.0):
        """(dipole_cmd_B (3-tuple, A.m2), wheel torque command (N.m))."""
        p = self.p
        mode = int(mode)
        if not 0 <= mode <= 9:
            raise ValueError(f"input mode = {mode} must be in [0, 9]")
        b2 = B[0] * B[0] + B[1] * B[1] + B[2] * B[2]
        sn = math.sqrt(sun[0] * sun[0] + sun[1] * sun[1] + sun[2] * sun[2])
        s = (sun[0] / sn, sun[1] / sn, sun[2] / sn) if sn > 0 else None
        H = self.total_momentum(omega, wheel_rate)
        m = (0.0, 0.0, 0.0)
        tw = 0.0
        field = b2 > B_MIN * B_MIN
        if mode == DETUMBLE:
            if field:
                m = (0.0, p["k_detumble"] * _cross(omega, B)[1] / b2, 0.0)
        elif mode in (SPINUP, REORIENT):
            if field:
                e_ref = None
                if mode == REORIENT and s is not None:
                    hold = p["reorient_hold_elevation"] if time_in_mode < p["reorient_duration"] else 0.0
                    e_ref = math.copysign(hold, s[1]) if hold > 0 else 0.0
                tau = self._momentum_torque(H, s if e_ref is not None else None, e_ref or 0.0)
                mx, _, mz = self._coil_dipole(tau, B, b2)
                m = (mx, p["k_nutation"] * _cross(omega, B)[1] / b2, mz)
        elif mode == DEPLOY_WHEEL:
            tw = p["k_wheel"] * p["Iy"] * omega[1]
        elif mode in (ACQUIRE, ORBIT_DAY, ORBIT_NIGHT):
            if field:
                m = self._coil_dipole(self._momentum_torque(H, s, 0.0, p["k_precession_fine"], True), B, b2)
            if s is not None:
                az = math.atan2(s[0], s[2]) if (s[0] != 0.0 or s[2] != 0.0) else 0.0
                w_ref = p["K_azimuth"] / p["D_azimuth"] * az
                lim = p["max_slew_rate"]
                w_ref = lim if w_ref > lim else (-lim if w_ref < -lim else w_ref)
                tw = -p["Iy"] * p["D_azimuth"] * (w_ref - omega[1])
        if not coils_enabled:
            m = (0.0, 0.0, 0.0)
        if not wheel_enabled:
            tw = 0.0
        return m, tw

    def get_state(self):
        return {}

    def set_state(self, state):
        pass
