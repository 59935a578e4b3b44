"""Sunline from ephemeris: the Sun heading in the body frame (the sunline module description).

The heading from the spacecraft to the Sun, from the two positions alone (no sun-sensor
filtering), rotated into B with the attitude:

    d_N = (r_SN_N - r_BN_N) / |r_SN_N - r_BN_N|      (module description Eq. 1: r_sun - r_sc, normalized)
    d_B = [BN(sigma_BN)] d_N                          (module description Eq. 2)

r_SN_N is the Sun's position and r_BN_N the spacecraft's, both in N (m). The attitude is the
MRP sigma_BN (Schaub and Junkins, components.core.mrp) or, equivalently, the scalar-last quaternion
q_BN with A(q) (components.core.rotations); both map N components to B components, and both give the
same heading (to rounding) for the same attitude, whichever MRP set or quaternion sign.

Limitation (as in the module description): the heading is only as good as the ephemeris; the Sun is treated
as a point, with no light-time or aberration correction.
"""
import math

from ..core import rotations, mrp
from ..core.checks import finite_vector

ATTITUDE_INPUTS = ("mrp", "quaternion")
# Positions closer than this fraction of their larger magnitude count as coinciding: the
# difference of two positions carries a rounding error of about 1e-16 of their magnitude.
REL_TOL = 1e-10


def sun_vector_N(r_SN_N, r_BN_N):
    """(unit heading d_N from the spacecraft to the Sun, distance |r_SN_N - r_BN_N| in m).

    ValueError, naming both positions, when they coincide: |r_SN_N - r_BN_N| <= REL_TOL times
    the larger of |r_SN_N|, |r_BN_N| (or exactly zero)."""
    rs = finite_vector(r_SN_N, 3, "Sun position r_SN_N", "m")
    rb = finite_vector(r_BN_N, 3, "spacecraft position r_BN_N", "m")
    d = (rs[0] - rb[0], rs[1] - rb[1], rs[2] - rb[2])
    dist = math.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
    scale = max(math.sqrt(rotations.dot(rs, rs)), math.sqrt(rotations.dot(rb, rb)))
    if dist == 0.0 or dist <= REL_TOL * scale:
        raise ValueError(f"Sun position r_SN_N {list(rs)} m and spacecraft position r_BN_N {list(rb)} m coincide "
                         f"(|r_SN_N - r_BN_N| = {dist:.3g} m, must exceed {REL_TOL:g} x {scale:.3g} m): "
                         "the Sun heading is undefined")
    return (d[0] / dist, d[1] / dist, d[2] / dist), dist


def _apply(C, v):
    return (C[0][0] * v[0] + C[0][1] * v[1] + C[0][2] * v[2],
            C[1][0] * v[0] + C[1][1] * v[1] + C[1][2] * v[2],
            C[2][0] * v[0] + C[2][1] * v[1] + C[2][2] * v[2])


def sun_heading_B(r_SN_N, r_BN_N, sigma_BN):
    """d_B = [BN(sigma_BN)] (r_SN_N - r_BN_N)/|r_SN_N - r_BN_N| (module description Eq. 1-2)."""
    d_N, _ = sun_vector_N(r_SN_N, r_BN_N)
    return _apply(mrp.to_dcm(sigma_BN), d_N)


def sun_heading_B_quaternion(r_SN_N, r_BN_N, q_BN):
    """d_B = A(q_BN) d_N, q_BN scalar last (normalized first; zero norm is a ValueError)."""
    d_N, _ = sun_vector_N(r_SN_N, r_BN_N)
    q = mrp.unit_quaternion(q_BN, "q_BN")
    return _apply(rotations.attitude_matrix(q), d_N)


class SunlineEphemeris:
    """Stateless model of the FMU: `attitude_input` ("mrp" or "quaternion") picks which
    attitude `heading()` uses."""

    def __init__(self, attitude_input="mrp"):
        if attitude_input not in ATTITUDE_INPUTS:
            raise ValueError(f"attitude_input = {attitude_input!r} must be one of "
                             f"{', '.join(map(repr, ATTITUDE_INPUTS))}")
        self.attitude_input = attitude_input

    def heading(self, r_SN_N, r_BN_N, sigma_BN=(0.0, 0.0, 0.0), q_BN=(0.0, 0.0, 0.0, 1.0)):
        """(d_B, distance in m) from the positions and the selected attitude."""
        d_N, dist = sun_vector_N(r_SN_N, r_BN_N)
        if self.attitude_input == "mrp":
            C = mrp.to_dcm(sigma_BN)
        else:
            C = rotations.attitude_matrix(mrp.unit_quaternion(q_BN, "q_BN"))
        return _apply(C, d_N), dist

    def get_state(self):
        return {}

    def set_state(self, state):
        if state not in ({}, None):
            raise ValueError(f"SunlineEphemeris has no state; got {state!r}")
