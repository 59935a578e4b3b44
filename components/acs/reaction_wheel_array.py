"""An array of up to six reaction wheels on arbitrary spin axes: motor torque commands in, wheel
speeds, the wheels' momentum and reaction torque in B, and the electrical power out.

The dynamics are those of Basilisk's balanced-wheel effector (reactionWheelStateEffector, model
BalancedWheels; Schaub and Junkins, Analytical Mechanics of Space Systems, sec. 4.5). For wheel i
with spin axis g_i (B), spin inertia J_i and speed Omega_i relative to the body, its absolute spin
momentum is H_i = J_i (g_i . omega_BN + Omega_i) and

    dH_i/dt = u_i + f_i                  (motor torque plus friction, about g_i)
    J_body omega_dot = L - sum g_i (u_i + f_i) - omega x (J_body omega + sum g_i H_i)

with J_body = I_sc - sum J_i g_i g_i^T, the spacecraft's inertia without the wheels' spin-axis
inertia (`body_inertia`). That second line is exactly the rigid body's gyrostat equation
(components.attitude.rigid_body) with wheel_torque_B = sum g_i (u_i + f_i) and
wheel_momentum_B = sum g_i H_i, which is what this array outputs: connecting the two and giving
the rigid body J_body flies Basilisk's equations, gyroscopic coupling included.

Over a communication step the applied torques are held (a zero-order hold, as Basilisk's
effector holds u between its UpdateState calls), so H_i advances exactly, H_i += (u_i + f_i) h,
and the rigid body's RK4 sees H(s) = H(t_k) + wheel_torque_B s, the same law.

The state is the spin momenta and the body rate at the last step's end (start() fixes both from
Omega0 and the start rate): the wheel speeds, limits and friction of a step are those at its
start, so the torque the body is given and the one the wheels integrate are the same, and no
output depends directly on the body-rate input (it is read when a step ends).

The command is limited in Basilisk's order: saturation to +-max_torque; below min_torque zero;
the power limit |u Omega| <= max_power (u = sign(u) max_power / |Omega|); no torque that would
speed a wheel up beyond max_speed once |Omega| >= max_speed (a step may end beyond it by the
step's own increment, as Basilisk's does). Friction (Basilisk's model without the Stribeck
term): f = -(coulomb sign(Omega) + viscous Omega), linear through zero below omega_limit_cycle
(f = -(coulomb + viscous omega_lc) Omega / omega_lc), evaluated at the step start and held.

Electrical power per wheel: base_power + u Omega / motor_efficiency when the motor drives the
wheel (u Omega > 0), base_power + regen_efficiency u Omega when it brakes it (0 by default: the
braking energy is dumped). The default wheel is the 10 mN.m.s, 1 mN.m, 6000 rpm class of
CubeSat wheels (J = 1.5e-5 kg.m2).
"""
import math

import numpy as np

from ..core.checks import finite_vector, positive

MAX_WHEELS = 6
RPM = 2.0 * math.pi / 60.0
DEFAULT_INERTIA = 1.5e-5  # kg.m2
DEFAULT_MAX_TORQUE = 1.0e-3  # N.m
DEFAULT_MAX_SPEED = 6000.0 * RPM  # rad/s
DEFAULT_MAX_POWER = 0.0  # W; 0: no power limit
DEFAULT_OMEGA_LIMIT_CYCLE = 1.0e-4  # rad/s, Basilisk's default
PYRAMID_ELEVATION = math.atan(1.0 / math.sqrt(2.0))  # 35.26 deg: equal torque and momentum on x, y and z


def pyramid_axes(elevation, count=4, azimuth0=math.radians(45.0)):
    """Spin axes of `count` wheels in a pyramid about +z: each tilted `elevation` (rad) from the
    xy plane, at azimuths azimuth0 + k 360/count."""
    return [(math.cos(elevation) * math.cos(azimuth0 + 2.0 * math.pi * k / count),
             math.cos(elevation) * math.sin(azimuth0 + 2.0 * math.pi * k / count),
             math.sin(elevation)) for k in range(count)]


def default_axes():
    """The FMUs' six slots: four wheels in a pyramid about +z (35.26 deg above the xy plane, at
    azimuths 45, 135, 225, 315 deg), then spare x and y wheels."""
    return pyramid_axes(PYRAMID_ELEVATION) + [(1.0, 0.0, 0.0), (0.0, 1.0, 0.0)]


def spin_inertia_B(axes, inertias):
    """sum J_i g_i g_i^T (kg.m2, 3x3): what the wheels' spin inertia adds to the body's."""
    G = _unit_axes(axes)
    return (G.T * np.asarray(inertias, dtype=float)) @ G


def body_inertia(spacecraft_inertia, axes, inertias):
    """The rigid body's inertia with these wheels: I_sc - sum J_i g_i g_i^T (see the module)."""
    return np.asarray(spacecraft_inertia, dtype=float).reshape(3, 3) - spin_inertia_B(axes, inertias)


def _unit_axes(axes):
    G = np.array([finite_vector(a, 3, f"spin axis {i + 1}", "B frame") for i, a in enumerate(axes)], dtype=float)
    n = np.linalg.norm(G, axis=1)
    if np.any(n < 1e-12):
        raise ValueError(f"spin axis {int(np.argmin(n)) + 1} is zero: every spin axis must be a non-zero 3-vector "
                         "(it is normalized)")
    return G / n[:, None]


def _per_wheel(name, values, count, unit, allow_zero=False):
    v = [float(x) for x in values]
    if len(v) != count:
        raise ValueError(f"{name} has {len(v)} values for {count} wheels")
    for i, x in enumerate(v):
        if not math.isfinite(x) or x < 0.0 or (x == 0.0 and not allow_zero):
            allowed = ">= 0" if allow_zero else "> 0"
            raise ValueError(f"{name} of wheel {i + 1} = {x!r} {unit} must be a finite number {allowed}")
    return np.array(v)


class ReactionWheelArray:
    def __init__(self, axes, inertias, max_torque, max_speed, max_power=None, min_torque=None, coulomb=None,
                 viscous=None, omega_limit_cycle=DEFAULT_OMEGA_LIMIT_CYCLE, speed0=None, base_power=None,
                 motor_efficiency=1.0, regen_efficiency=0.0):
        count = len(axes)
        if not 1 <= count <= MAX_WHEELS:
            raise ValueError(f"wheel_count = {count} must be in 1..{MAX_WHEELS}")
        zeros = [0.0] * count
        self.count = count
        self.G = _unit_axes(axes)  # rows: spin axes g_i in B
        self.J = _per_wheel("J_s", inertias, count, "kg.m2")
        self.max_torque = _per_wheel("max_torque", max_torque, count, "N.m")
        self.max_speed = _per_wheel("max_speed", max_speed, count, "rad/s")
        self.max_power = _per_wheel("max_power", zeros if max_power is None else max_power, count, "W", True)
        self.min_torque = _per_wheel("min_torque", zeros if min_torque is None else min_torque, count, "N.m", True)
        self.coulomb = _per_wheel("coulomb_friction", zeros if coulomb is None else coulomb, count, "N.m", True)
        self.viscous = _per_wheel("viscous_friction", zeros if viscous is None else viscous, count, "N.m.s", True)
        self.base_power = _per_wheel("base_power", zeros if base_power is None else base_power, count, "W", True)
        self.omega_limit_cycle = positive("omega_limit_cycle", omega_limit_cycle, "rad/s")
        self.motor_efficiency = positive("motor_efficiency", motor_efficiency)
        if self.motor_efficiency > 1.0:
            raise ValueError(f"motor_efficiency = {motor_efficiency!r} must be in (0, 1]")
        self.regen_efficiency = float(regen_efficiency)
        if not 0.0 <= self.regen_efficiency <= 1.0:
            raise ValueError(f"regen_efficiency = {regen_efficiency!r} must be in [0, 1]")
        speed0 = np.array(finite_vector(zeros if speed0 is None else speed0, count, "Omega0", "rad/s"))
        if np.any(np.abs(speed0) > self.max_speed):
            i = int(np.argmax(np.abs(speed0) - self.max_speed))
            raise ValueError(f"Omega0 of wheel {i + 1} = {float(speed0[i])!r} rad/s must be within +-max_speed "
                             f"({float(self.max_speed[i])!r} rad/s)")
        self.speed0 = speed0
        self.H = None  # absolute spin momenta (the state), set by start()
        self.omega_ref = None  # the body rate the wheel speeds refer to: the last step's end

    # ---- state -------------------------------------------------------------------------------
    def start(self, omega_BN_B):
        """Fix the spin momenta from Omega0 relative to this body rate (the start of the run)."""
        self.omega_ref = np.array(finite_vector(omega_BN_B, 3, "omega_BN_B", "rad/s"))
        self.H = self.J * (self.speed0 + self.G @ self.omega_ref)

    def _started(self):
        if self.H is None:
            raise RuntimeError("ReactionWheelArray.start(omega_BN_B) must fix the spin momenta before it is used")

    def speeds(self):
        """Omega_i = H_i / J_i - g_i . omega_BN_B (rad/s, relative to the body, at the body rate of
        the last step's end)."""
        self._started()
        return self.H / self.J - self.G @ self.omega_ref

    def momentum_B(self):
        """sum g_i H_i (N.m.s, B): the wheels' absolute spin momentum, the rigid body's wheel_momentum_B."""
        self._started()
        return self.G.T @ self.H

    # ---- torques -----------------------------------------------------------------------------
    def motor_torques(self, commands, speeds, enabled=True, available=None):
        """The motor torques u_i (N.m) the commands give at these wheel speeds (see the module)."""
        u = np.array(finite_vector(commands, self.count, "torque_cmd", "N.m"))
        if not enabled:
            return np.zeros(self.count)
        if available is not None:
            u = np.where(np.asarray(available, dtype=bool), u, 0.0)
        u = np.clip(u, -self.max_torque, self.max_torque)
        u[np.abs(u) < self.min_torque] = 0.0
        limited = (self.max_power > 0.0) & (np.abs(u * speeds) >= self.max_power)
        if np.any(limited):
            u[limited] = np.copysign(self.max_power[limited] / np.abs(speeds[limited]), u[limited])
        u[(np.abs(speeds) >= self.max_speed) & (speeds * u >= 0.0)] = 0.0
        return u

    def friction_torques(self, speeds):
        """f_i (N.m): Coulomb and viscous friction opposing the spin, linear below omega_limit_cycle."""
        w_lc = self.omega_limit_cycle
        f = np.sign(speeds) * self.coulomb + self.viscous * speeds
        slow = np.abs(speeds) < w_lc
        f[slow] = (self.coulomb[slow] + self.viscous[slow] * w_lc) / w_lc * speeds[slow]
        return -f

    def evaluate(self, commands, enabled=True, available=None):
        """(speeds, motor torques u, applied torques u + f, wheel_torque_B, wheel_momentum_B,
        electrical power per wheel) at the current state."""
        speeds = self.speeds()
        u = self.motor_torques(commands, speeds, enabled, available)
        applied = u + self.friction_torques(speeds)
        mechanical = u * speeds
        power = self.base_power + np.where(mechanical > 0.0, mechanical / self.motor_efficiency,
                                           self.regen_efficiency * mechanical)
        return speeds, u, applied, self.G.T @ applied, self.momentum_B(), power

    def step(self, commands, h, omega_BN_B_end, enabled=True, available=None):
        """Advance h seconds with the torques of the step start held; the wheel speeds then refer
        to the body rate at the step's end, omega_BN_B_end."""
        applied = self.evaluate(commands, enabled, available)[2]
        self.H = self.H + applied * h
        self.omega_ref = np.array(finite_vector(omega_BN_B_end, 3, "omega_BN_B", "rad/s"))

    def get_state(self):
        return {"H": None if self.H is None else self.H.tolist(),
                "omega_ref": None if self.omega_ref is None else self.omega_ref.tolist()}

    def set_state(self, state):
        self.H = None if state["H"] is None else np.array(state["H"], dtype=float)
        self.omega_ref = None if state["omega_ref"] is None else np.array(state["omega_ref"], dtype=float)
