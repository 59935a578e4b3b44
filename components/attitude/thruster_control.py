"""Thruster-pair torque levels and the threshold logic the thesis' controllers share.

Thesis Eq. 13-16 and Appendix A: each body axis has thruster pairs that apply a fixed torque
of either sign; a commanded torque at or above the pair torque fires the pair (saturating at
the pair torque), a smaller command fires nothing (Appendix C, every controller).
"""
import math

import numpy as np

from ..mission.neighbor import SPACECRAFT

F_THRUSTER = SPACECRAFT.rcs_thrust  # N, one cold-gas RCS thruster (MarCO heritage, Appendix A)


def pair_torques(force=F_THRUSTER, a=SPACECRAFT.edge_a, c=SPACECRAFT.edge_c):
    """Torque of one thruster pair about x, y, z (Eq. 16, Appendix A `Lx`, `Ly`, `Lz`).

    x: two thrusters at +-a/2 from the axis;  y and z: one thruster at c/2 and one at
    c/2 - c/3 from the axis, pushing in opposite senses. With F = 25 mN, a = 0.1 m and
    c = 0.3 m all three are 2.5 mN.m.
    """
    for name, value in (("thruster force", force), ("edge a", a), ("edge c", c)):
        if not (math.isfinite(value) and value > 0):
            raise ValueError(f"{name} = {value!r} must be a finite positive number")
    lx = (a / 2) * (2 * force)
    ly = (c / 2) * force - ((c / 2) - (c / 3)) * force
    return (lx, ly, ly)


def check_levels(levels):
    levels = tuple(float(x) for x in levels)
    if len(levels) != 3 or not all(math.isfinite(x) and x > 0 for x in levels):
        raise ValueError(f"torque_level {list(levels)} must be three finite positive torques (N.m)")
    return levels


def quantize(command, levels, thresholds=None):
    """Saturate each axis to +-level, zero below it (Appendix C). Returns (torque, flags).
    `thresholds` (default: the levels) raises the command at which a pair fires."""
    thresholds = levels if thresholds is None else thresholds
    torque = [0.0, 0.0, 0.0]
    flags = [0, 0, 0]
    for i in range(3):
        if command[i] >= thresholds[i]:
            torque[i], flags[i] = levels[i], 1
        elif command[i] <= -thresholds[i]:
            torque[i], flags[i] = -levels[i], -1
    return torque, flags


def nearest_pair_flags(command, levels):
    """-1/0/+1 per axis: the pair torque in {-L, 0, +L} nearest the commanded torque (the thruster
    models' rounding: a controller's already-quantized command passes through unchanged)."""
    out = []
    for i in range(3):
        c, half = command[i], 0.5 * levels[i]
        if not math.isfinite(c):
            raise ValueError(f"torque_cmd_B[{i + 1}] = {c!r} must be finite")
        out.append(1 if c >= half else (-1 if c <= -half else 0))
    return out


def impulse_bit_rates(levels, inertia_diagonal, min_on_time):
    """Rate change (rad/s) one firing of the minimum on-time gives about each axis, L t_min / I_ii:
    the smallest correction the RCS can make, which a stop window or a rate deadband narrower
    than it can only meet by chance (the thesis' 0.01 deg/s window against 0.017-0.043 deg/s
    per 15 ms pulse)."""
    levels = check_levels(levels)
    if not (math.isfinite(min_on_time) and min_on_time > 0):
        raise ValueError(f"minimum on-time = {min_on_time!r} s must be a finite positive number")
    out = []
    for i, inertia in enumerate(inertia_diagonal):
        if not (math.isfinite(inertia) and inertia > 0):
            raise ValueError(f"inertia I[{i + 1},{i + 1}] = {inertia!r} kg.m2 must be a finite positive number")
        out.append(levels[i] * min_on_time / inertia)
    return tuple(out)


class SettleTimer:
    """Settle criterion: a maneuver is done once its stop test has held for `dwell` seconds (0:
    the thesis' single-sample test). advance() at the end of each step with the test's value at
    the step's start; leaving the tolerance, or a disabled controller, restarts the count."""

    def __init__(self, dwell=0.0):
        dwell = float(dwell)
        if not (math.isfinite(dwell) and dwell >= 0):
            raise ValueError(f"settle_time = {dwell!r} s must be a finite number >= 0")
        self.dwell = dwell
        self.cell = np.zeros(1)  # time_inside, in an array that a native step advances in place

    @property
    def time_inside(self):
        return float(self.cell[0])

    @time_inside.setter
    def time_inside(self, value):
        self.cell[0] = value

    def done(self, inside):
        return bool(inside) and self.time_inside >= self.dwell

    def advance(self, inside, h, enabled=True):
        self.time_inside = self.time_inside + h if (inside and enabled) else 0.0


def check_gains(name, gains, allow_zero=True):
    gains = tuple(float(x) for x in gains)
    ok = all(math.isfinite(x) and (x >= 0 if allow_zero else x > 0) for x in gains)
    if len(gains) != 3 or not ok:
        kind = "non-negative" if allow_zero else "positive"
        raise ValueError(f"{name} {list(gains)} must be three finite {kind} numbers")
    return gains
