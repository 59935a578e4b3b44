"""TRIAD attitude determination and gyro propagation (thesis section 3.3.1).

The thesis' estimator "assumes knowledge of two unit vectors in the host spacecraft's body
frame as well as a reference inertial frame and also assumes that one measurement is more
accurate than the other": the TRIAD algorithm (Black 1964; Shuster and Oh 1981; Markley and
Crassidis 2014, section 5.2). From body vectors b1 (the more accurate), b2 and their reference
directions r1, r2 in N it builds the orthonormal triads

    b1,  b2' = (b1 x b2)/|b1 x b2|,  b3' = b1 x b2'      (same for r1, r2)

and the attitude matrix A = [b1 b2' b3'] [r1 r2' r3']^T, which maps N to B exactly like
components.core.rotations.attitude_matrix(q_BN). b1 is reproduced exactly; b2 only fixes the
rotation about b1.

Between fixes the estimate is propagated with the measured rate, held constant over a step:
q(t+h) = q_rot (x) q(t), q_rot = [sin(|w| h/2) w/|w|; cos(|w| h/2)], the exact solution of
q_dot = 1/2 Xi(q) w (thesis Eq. 19) for constant w, then normalized.

First-order TRIAD error (used by the tests): with error angles of RMS s1, s2 about random
axes perpendicular to b1, b2 (per-axis variance s^2/2) and theta the angle between them,
E|dtheta|^2 = s1^2 + (s2^2 + cos^2(theta) s1^2) / (2 sin^2 theta).
"""
import math

from ..core import rotations
from .sensors import check_sigma, unit_vector


def _unit(v, what):
    v = tuple(float(x) for x in v)
    if len(v) != 3 or not all(math.isfinite(x) for x in v):
        raise ValueError(f"{what} {list(v)} must be 3 finite numbers")
    return unit_vector(v, what)


def _triad_basis(v1, v2, what, min_sin):
    c = rotations.cross(v1, v2)
    s = rotations.norm(c)
    if s <= min_sin:
        raise ValueError(f"{what} vectors are parallel or nearly so (|v1 x v2| = {s:.3g} <= {min_sin:.3g}); "
                         "TRIAD needs two non-parallel directions")
    v2p = (c[0] / s, c[1] / s, c[2] / s)
    return v1, v2p, rotations.cross(v1, v2p)


def triad(b1, b2, r1, r2, min_sin=1e-9):
    """Attitude matrix A (N to B, 3x3 nested tuple) from body vectors b1, b2 and reference
    vectors r1, r2 (normalized here); b1/r1 is the trusted pair. ValueError when either pair
    is (nearly) parallel: |v1 x v2| <= min_sin for the unit vectors."""
    B = _triad_basis(_unit(b1, "b1"), _unit(b2, "b2"), "body", min_sin)
    R = _triad_basis(_unit(r1, "r1"), _unit(r2, "r2"), "reference", min_sin)
    # A[i][j] = sum_k B_k[i] R_k[j]
    return tuple(tuple(B[0][i] * R[0][j] + B[1][i] * R[1][j] + B[2][i] * R[2][j] for j in range(3))
                 for i in range(3))


def dcm_to_quaternion(A):
    """Quaternion q (scalar last, q4 >= 0) with attitude.attitude_matrix(q) == A (Shepperd's
    method, components.core.rotations.dcm_to_quaternion), after checking A is 3x3 and finite."""
    A = [[float(x) for x in row] for row in A]
    if len(A) != 3 or any(len(row) != 3 for row in A) or not all(math.isfinite(x) for row in A for x in row):
        raise ValueError("attitude matrix must be 3x3 with finite entries")
    return rotations.dcm_to_quaternion(A)


def triad_quaternion(b1, b2, r1, r2, min_sin=1e-9):
    return dcm_to_quaternion(triad(b1, b2, r1, r2, min_sin))


def propagate(q, omega, h):
    """Rotate q_BN over h with the body rate omega held constant (exact), normalized."""
    wn = rotations.norm(omega)
    if wn == 0.0 or h == 0.0:
        return rotations.normalized(q)
    dq = rotations.from_axis_angle(omega, wn * h)
    return rotations.normalized(rotations.circle_cross(dq, q))


def error_angle(q_est, q_true):
    """Rotation angle (rad) between two attitudes, 2 acos|<q_est, q_true>| (sign-free)."""
    e = rotations.circle_cross(rotations.normalized(q_est), rotations.conjugate(rotations.normalized(q_true)))
    # 2 atan2(|e_v|, |e_4|) is accurate near zero, where 2 acos|e_4| is not
    return 2.0 * math.atan2(rotations.norm(e[:3]), abs(e[3]))


def triad_error_rms(s1, s2, theta):
    """First-order RMS attitude error (rad) of TRIAD with b1 of error RMS s1 first, b2 of RMS s2
    (error angles about random perpendicular axes), theta the angle between b1 and b2."""
    s, c = math.sin(theta), math.cos(theta)
    return math.sqrt(s1 * s1 + (s2 * s2 + c * c * s1 * s1) / (2.0 * s * s))


class AttitudeDetermination:
    """TRIAD fixes from nadir and Sun vectors, gyro propagation in between.

    The trusted (first) vector is the nadir when nadir_sigma <= sun_sigma (the horizon sensor,
    as in the thesis), else the Sun. A fix needs both vectors valid and at least
    `min_separation` (rad) apart (TRIAD's error grows as 1/sin of the angle between them).

    State: the estimate q propagated to the current communication point (used when there is
    no fix), the time since the last fix, whether there was one.
    """

    def __init__(self, nadir_sigma=math.radians(0.25), sun_sigma=math.radians(0.5) / 3.0,
                 q0=(0.0, 0.0, 0.0, 1.0), min_separation=math.radians(5.0)):
        self.nadir_sigma = check_sigma("nadir_sigma", nadir_sigma, "rad")
        self.sun_sigma = check_sigma("sun_sigma", sun_sigma, "rad")
        min_separation = float(min_separation)
        if not (math.isfinite(min_separation) and 0.0 <= min_separation < math.pi / 2):
            raise ValueError(f"min_separation = {min_separation!r} must be in [0, pi/2) rad")
        self.min_separation = min_separation
        self.min_sin = max(1e-9, math.sin(min_separation))
        self.nadir_first = self.nadir_sigma <= self.sun_sigma
        self.q = rotations.normalized(tuple(float(x) for x in q0), "q0")
        self.time_since_fix = 0.0
        self.has_fix = False

    def fix(self, nadir_B, nadir_valid, sun_B, sun_valid, r_BN_N, r_SN_N):
        """TRIAD q_BN from the current measurements, or None when no fix is possible."""
        if not (nadir_valid and sun_valid):
            return None
        try:
            nadir_N = _unit([-x for x in r_BN_N], "nadir reference -r_BN_N")
            sun_N = _unit([s - r for s, r in zip(r_SN_N, r_BN_N)], "Sun reference r_SN_N - r_BN_N")
            nb, sb = _unit(nadir_B, "nadir_B"), _unit(sun_B, "sun_B")
            if self.nadir_first:
                return triad_quaternion(nb, sb, nadir_N, sun_N, self.min_sin)
            return triad_quaternion(sb, nb, sun_N, nadir_N, self.min_sin)
        except ValueError:
            return None  # zero, non-finite or (nearly) parallel vectors: no fix, keep propagating

    def estimate(self, *measurements):
        """(q_est_BN, fix, time_since_fix) at the current communication point."""
        q = self.fix(*measurements)
        if q is not None:
            return q, True, 0.0
        return self.q, False, self.time_since_fix

    def step(self, measurements, omega_meas_B, h):
        """From the estimate at t (a fix if possible), propagate with the gyro rate to t + h."""
        q, fixed, tsf = self.estimate(*measurements)
        self.has_fix = self.has_fix or fixed
        w = tuple(float(x) for x in omega_meas_B)
        if not all(math.isfinite(x) for x in w):
            raise ValueError(f"omega_meas_B {list(w)} must be finite")
        self.q = propagate(q, w, h)
        self.time_since_fix = tsf + h

    def get_state(self):
        return {"q": list(self.q), "time_since_fix": self.time_since_fix, "has_fix": self.has_fix}

    def set_state(self, state):
        self.q = tuple(float(x) for x in state["q"])
        self.time_since_fix = float(state["time_since_fix"])
        self.has_fix = bool(state["has_fix"])
