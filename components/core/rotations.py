"""Quaternion and Euler-angle helpers (thesis Eq. 19-29, 41-44, 52).

Quaternions are scalar-last, q = [q1, q2, q3, q4] with q4 the scalar part (Markley and
Crassidis, the thesis' convention). The product is the thesis' "circle cross" (Eq. 42):

    p (x) q = [p4 q_v + q4 p_v - p_v x q_v ;  p4 q4 - p_v . q_v]

With this product, successive rotations compose as q_total = q_second (x) q_first, and the
attitude matrix A(q) (Eq. 22) maps N-frame components to B-frame components.

These run once per communication step on 3- and 4-vectors, where plain float arithmetic is
several times faster than numpy's per-call overhead, so they work on tuples/lists of floats.
"""
import math

from .jit import njit


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def norm(v):
    # written out for 3- and 4-vectors (a generator through sum() costs about 1 us a call, and the
    # mission takes millions); the same additions in the same order, so the same bits
    if len(v) == 3:
        return math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    if len(v) == 4:
        return math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + v[3] * v[3])
    return math.sqrt(sum(x * x for x in v))


def circle_cross(p, q):
    """Quaternion product p (x) q of Eq. 42 (p4 q_v + q4 p_v - p_v x q_v; p4 q4 - p_v . q_v),
    written out: the same operations in the same order as through cross() and dot()."""
    p1, p2, p3, p4 = p
    q1, q2, q3, q4 = q
    return (p4 * q1 + q4 * p1 - (p2 * q3 - p3 * q2),
            p4 * q2 + q4 * p2 - (p3 * q1 - p1 * q3),
            p4 * q3 + q4 * p3 - (p1 * q2 - p2 * q1),
            p4 * q4 - (p1 * q1 + p2 * q2 + p3 * q3))


def conjugate(q):
    """Eq. 44."""
    return (-q[0], -q[1], -q[2], q[3])


def inverse(q):
    """Eq. 43 as written in Appendix C: the conjugate divided by the norm.

    The thesis' scripts divide by ||q|| (not ||q||^2 as Eq. 43 reads); for the unit
    quaternions the controllers receive as targets the two agree, and the scripts are what
    the published numbers came from.
    """
    n = norm(q)
    return (-q[0] / n, -q[1] / n, -q[2] / n, q[3] / n)


def error_quaternion(q, q_d):
    """delta_q = q (x) q_d^-1 (Eq. 41)."""
    return circle_cross(q, inverse(q_d))


def xi(q):
    """Xi(q) of Eq. 20 as a 4x3 nested tuple."""
    q1, q2, q3, q4 = q
    return ((q4, -q3, q2), (q3, q4, -q1), (-q2, q1, q4), (-q1, -q2, -q3))


def quaternion_rate(q, w):
    """q_dot = 1/2 Xi(q) omega (Eq. 19), written out."""
    q1, q2, q3, q4 = q
    w1, w2, w3 = w
    return (0.5 * (q4 * w1 - q3 * w2 + q2 * w3),
            0.5 * (q3 * w1 + q4 * w2 - q1 * w3),
            0.5 * (-q2 * w1 + q1 * w2 + q4 * w3),
            0.5 * (-q1 * w1 - q2 * w2 - q3 * w3))


@njit(cache=True, plain_first=True)
def quaternion_rate_kernel(q1, q2, q3, q4, w1, w2, w3):
    """quaternion_rate on floats, for compiled callers (the rigid body's RK4, the MEKF's update):
    the same operations."""
    return (0.5 * (q4 * w1 - q3 * w2 + q2 * w3),
            0.5 * (q3 * w1 + q4 * w2 - q1 * w3),
            0.5 * (-q2 * w1 + q1 * w2 + q4 * w3),
            0.5 * (-q1 * w1 - q2 * w2 - q3 * w3))


def normalized(q, what="quaternion"):
    n = norm(q)
    if not math.isfinite(n) or n < 1e-12:
        raise ValueError(f"{what} {list(q)} has zero or non-finite norm; give a non-zero quaternion")
    if len(q) == 4:  # written out (millions of calls)
        return (q[0] / n, q[1] / n, q[2] / n, q[3] / n)
    if len(q) == 3:
        return (q[0] / n, q[1] / n, q[2] / n)
    return tuple(x / n for x in q)


def from_axis_angle(axis, angle):
    """Eq. 52: rotation by `angle` (rad) about unit `axis`."""
    e = normalized(axis, "rotation axis")
    s = math.sin(angle / 2.0)
    return (e[0] * s, e[1] * s, e[2] * s, math.cos(angle / 2.0))


def attitude_matrix(q):
    """A(q) of Eq. 22 for a unit quaternion (rows: B axes in N components)."""
    q1, q2, q3, q4 = q
    return ((q1 * q1 - q2 * q2 - q3 * q3 + q4 * q4, 2 * (q1 * q2 + q3 * q4), 2 * (q1 * q3 - q2 * q4)),
            (2 * (q1 * q2 - q3 * q4), -q1 * q1 + q2 * q2 - q3 * q3 + q4 * q4, 2 * (q2 * q3 + q1 * q4)),
            (2 * (q1 * q3 + q2 * q4), 2 * (q2 * q3 - q1 * q4), -q1 * q1 - q2 * q2 + q3 * q3 + q4 * q4))


def dcm_to_quaternion(C):
    """Unit q (scalar last, q4 >= 0) with attitude_matrix(q) == C, by Shepperd's method: the
    largest of 4 q4^2 - 1 = tr C and 4 qi^2 - 1 = 2 C_ii - tr C comes from the diagonal, the
    other elements from off-diagonal sums and differences. C is not checked for
    orthonormality (callers that take a DCM from outside check it); the result is
    normalized, so a nearly orthonormal C gives the quaternion of a nearby rotation."""
    tr = C[0][0] + C[1][1] + C[2][2]
    cands = (tr, C[0][0], C[1][1], C[2][2])
    k = max(range(4), key=lambda i: cands[i])
    if k == 0:
        q4 = 0.5 * math.sqrt(max(0.0, 1.0 + tr))
        f = 0.25 / q4
        q = ((C[1][2] - C[2][1]) * f, (C[2][0] - C[0][2]) * f, (C[0][1] - C[1][0]) * f, q4)
    elif k == 1:
        q1 = 0.5 * math.sqrt(max(0.0, 1.0 + 2.0 * C[0][0] - tr))
        f = 0.25 / q1
        q = (q1, (C[0][1] + C[1][0]) * f, (C[0][2] + C[2][0]) * f, (C[1][2] - C[2][1]) * f)
    elif k == 2:
        q2 = 0.5 * math.sqrt(max(0.0, 1.0 + 2.0 * C[1][1] - tr))
        f = 0.25 / q2
        q = ((C[0][1] + C[1][0]) * f, q2, (C[1][2] + C[2][1]) * f, (C[2][0] - C[0][2]) * f)
    else:
        q3 = 0.5 * math.sqrt(max(0.0, 1.0 + 2.0 * C[2][2] - tr))
        f = 0.25 / q3
        q = ((C[0][2] + C[2][0]) * f, (C[1][2] + C[2][1]) * f, q3, (C[0][1] - C[1][0]) * f)
    q = normalized(q, "quaternion of the attitude matrix")
    return q if q[3] >= 0.0 else tuple(-x for x in q)


def euler123(q):
    """1-2-3 Euler angles (phi, theta, psi) in rad from q (Eq. 25-29, Appendix C q_to_Euler).

    q is normalized first, so a quaternion whose norm drifted under the thesis' explicit Euler
    integration still gives angles of the attitude it represents. theta is in [-pi/2, pi/2],
    phi and psi in (-pi, pi].
    """
    A = attitude_matrix(normalized(q))
    s = max(-1.0, min(1.0, A[2][0]))
    return (math.atan2(-A[2][1], A[2][2]), math.asin(s), math.atan2(-A[1][0], A[0][0]))


def from_euler123(phi, theta, psi):
    """Quaternion of D123 = D(e3, psi) D(e2, theta) D(e1, phi) (Eq. 25)."""
    qx = from_axis_angle((1.0, 0.0, 0.0), phi)
    qy = from_axis_angle((0.0, 1.0, 0.0), theta)
    qz = from_axis_angle((0.0, 0.0, 1.0), psi)
    return circle_cross(qz, circle_cross(qy, qx))


def sign(x):
    """sign() with sign(0) = 0, as FreeFlyer's sign and numpy.sign define it."""
    return (x > 0) - (x < 0)
