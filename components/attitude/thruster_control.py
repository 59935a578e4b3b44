"""Thruster-pair torque levels and the threshold logic the thesis' controllers share.

Thesis Eq. 13-16 and Appendix A: each body axis has thruster pairs that apply a fixed torque
of either sign; a commanded torque at or above the pair torque fires the pair (saturating at
the pair torque), a smaller command fires nothing (Appendix C, every controller).
"""
import math

F_THRUSTER = 0.025  # N, one cold-gas RCS thruster (MarCO heritage, Appendix A)


def pair_torques(force=F_THRUSTER, a=0.1, c=0.3):
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


def quantize(command, levels):
    """Saturate each axis to +-level, zero below it (Appendix C). Returns (torque, flags)."""
    torque = [0.0, 0.0, 0.0]
    flags = [0, 0, 0]
    for i in range(3):
        if command[i] >= levels[i]:
            torque[i], flags[i] = levels[i], 1
        elif command[i] <= -levels[i]:
            torque[i], flags[i] = -levels[i], -1
    return torque, flags


def check_gains(name, gains, allow_zero=True):
    gains = tuple(float(x) for x in gains)
    ok = all(math.isfinite(x) and (x >= 0 if allow_zero else x > 0) for x in gains)
    if len(gains) != 3 or not ok:
        kind = "non-negative" if allow_zero else "positive"
        raise ValueError(f"{name} {list(gains)} must be three finite {kind} numbers")
    return gains
