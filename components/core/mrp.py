"""Modified Rodrigues Parameters (MRP) `sigma_BN`: the one place for MRP conversions.

Convention: Schaub and Junkins, "Analytical Mechanics of Space Systems" (MRPs, Sec. 3.5),
written with our scalar-last quaternion q = [q1, q2, q3, q4] (q4 the scalar part; Markley and
Crassidis, docs/conventions.md). Schaub's Euler parameters (beta0, beta1, beta2, beta3) are
(q4, q1, q2, q3), and Schaub's [BN(beta)] is exactly Markley's A(q) (both map N-frame
components to B-frame components), so

    sigma = q_1:3 / (1 + q4)                                   quaternion -> MRP
    q_1:3 = 2 sigma / (1 + s2),  q4 = (1 - s2) / (1 + s2)     MRP -> quaternion, s2 = |sigma|^2
    [BN(sigma)] = I + (8 [sigma~]^2 - 4 (1 - s2) [sigma~]) / (1 + s2)^2
    sigma_s = -sigma / s2                                      shadow set

and [BN(sigma(q))] == components.core.rotations.attitude_matrix(q) for every unit q (tested for q and
-q). [sigma~] is the cross-product matrix ([sigma~] v = sigma x v).

q and -q give the same attitude; their MRPs are each other's shadow sets (sigma(-q) =
-q_1:3 / (1 - q4) = sigma_s(q)). The "short" set has |sigma| <= 1 (rotation angle <= 180 deg);
`short()` switches to it and `from_quaternion(q, short=True)` returns it directly. sigma is
singular (infinite) for a 360 deg rotation, q4 = -1: `from_quaternion(q)` refuses it and
`from_quaternion(q, short=True)` uses -q.

Everything works on tuples of floats (plain float arithmetic beats numpy on 3-vectors).
"""
import math

from . import rotations
from .checks import finite_vector


def unit_quaternion(q, what="q_BN"):
    """q (4 finite numbers, scalar last) normalized; ValueError naming `what` otherwise."""
    return rotations.normalized(finite_vector(q, 4, what, "scalar last"), what)


def from_quaternion(q, short=False):
    """sigma = q_1:3 / (1 + q4) of the (normalized) scalar-last quaternion q.

    short=True returns the short set (|sigma| <= 1) by using -q when q4 < 0. With short=False
    a quaternion with q4 = -1 (to 1e-12, a 360 deg rotation, where sigma is infinite) is a
    ValueError."""
    q1, q2, q3, q4 = unit_quaternion(q)
    if short and q4 < 0.0:
        q1, q2, q3, q4 = -q1, -q2, -q3, -q4
    d = 1.0 + q4
    if d < 1e-12:
        raise ValueError(f"q_BN {[q1, q2, q3, q4]} has q4 = -1: its MRP sigma = q_1:3/(1 + q4) is infinite; "
                         "use -q (short=True) for the same attitude")
    return (q1 / d, q2 / d, q3 / d)


def to_quaternion(sigma):
    """Unit scalar-last quaternion of sigma: q_1:3 = 2 sigma/(1 + s2), q4 = (1 - s2)/(1 + s2).

    The short set gives q4 >= 0, its shadow set the opposite quaternion (same attitude)."""
    s1, s2, s3 = finite_vector(sigma, 3, "sigma_BN")
    ss = s1 * s1 + s2 * s2 + s3 * s3
    d = 1.0 + ss
    return (2.0 * s1 / d, 2.0 * s2 / d, 2.0 * s3 / d, (1.0 - ss) / d)


def shadow(sigma):
    """Shadow set sigma_s = -sigma / |sigma|^2 (same attitude; the zero MRP has none)."""
    s1, s2, s3 = finite_vector(sigma, 3, "sigma_BN")
    ss = s1 * s1 + s2 * s2 + s3 * s3
    if ss == 0.0:
        raise ValueError("sigma_BN = [0, 0, 0] (zero rotation) has no shadow set (it would be infinite)")
    return (-s1 / ss, -s2 / ss, -s3 / ss)


def short(sigma):
    """The short set of sigma: sigma itself if |sigma| <= 1, else its shadow set."""
    s1, s2, s3 = finite_vector(sigma, 3, "sigma_BN")
    ss = s1 * s1 + s2 * s2 + s3 * s3
    if ss > 1.0:
        return (-s1 / ss, -s2 / ss, -s3 / ss)
    return (s1, s2, s3)


def to_dcm(sigma):
    """[BN(sigma)] = I + (8 [s~]^2 - 4 (1 - s2) [s~]) / (1 + s2)^2 (Schaub and Junkins), as a
    3x3 nested tuple mapping N-frame components to B-frame components (= A(q))."""
    s1, s2, s3 = finite_vector(sigma, 3, "sigma_BN")
    ss = s1 * s1 + s2 * s2 + s3 * s3
    d = 1.0 + ss
    k8 = 8.0 / (d * d)
    k4 = 4.0 * (1.0 - ss) / (d * d)
    # [s~]^2 = s s^T - s2 I
    return ((1.0 + k8 * (s1 * s1 - ss), k8 * s1 * s2 + k4 * s3, k8 * s1 * s3 - k4 * s2),
            (k8 * s2 * s1 - k4 * s3, 1.0 + k8 * (s2 * s2 - ss), k8 * s2 * s3 + k4 * s1),
            (k8 * s3 * s1 + k4 * s2, k8 * s3 * s2 - k4 * s1, 1.0 + k8 * (s3 * s3 - ss)))


def dcm_to_quaternion(C, tol=1e-6):
    """Unit scalar-last quaternion q (q4 >= 0) with attitude_matrix(q) == C (Shepperd's method).

    C must be a rotation matrix: orthonormal with determinant +1 to `tol`, else ValueError."""
    try:
        C = tuple(tuple(float(x) for x in row) for row in C)
    except (TypeError, ValueError):
        raise ValueError(f"DCM must be a 3x3 matrix of numbers, got {C!r}") from None
    if len(C) != 3 or any(len(r) != 3 for r in C) or not all(math.isfinite(x) for r in C for x in r):
        raise ValueError(f"DCM {C} must be a 3x3 matrix of finite numbers")
    for i in range(3):
        for j in range(3):
            e = sum(C[i][k] * C[j][k] for k in range(3)) - (1.0 if i == j else 0.0)
            if abs(e) > tol:
                raise ValueError(f"DCM {C} is not orthonormal (C C^T differs from I by {e:.3g} at ({i + 1},{j + 1}); "
                                 f"allowed {tol:g})")
    det = rotations.dot(C[0], rotations.cross(C[1], C[2]))
    if abs(det - 1.0) > tol:
        raise ValueError(f"DCM {C} has determinant {det!r}; a rotation needs +1 (to {tol:g})")
    return rotations.dcm_to_quaternion(C)


def from_dcm(C, tol=1e-6):
    """Short-set MRP (|sigma| <= 1) of the rotation matrix C = [BN] (via Shepperd's quaternion)."""
    return from_quaternion(dcm_to_quaternion(C, tol), short=True)


def rotate(sigma, v):
    """[BN(sigma)] v: N-frame components v to B-frame components."""
    C = to_dcm(sigma)
    return (C[0][0] * v[0] + C[0][1] * v[1] + C[0][2] * v[2],
            C[1][0] * v[0] + C[1][1] * v[1] + C[1][2] * v[2],
            C[2][0] * v[0] + C[2][1] * v[1] + C[2][2] * v[2])
