"""Multiplicative extended Kalman filter for attitude and gyro bias (thesis section 3.3.1).

The thesis determines the attitude with TRIAD (horizon and Sun sensors) and then propagates
it with a 3-axis gyro through an extended Kalman filter [44]. This is the standard MEKF of
Markley and Crassidis (2014, section 6.2; Lefferts, Markley and Shuster 1982):

state       q_BN (scalar last, kept unit) and the gyro bias b (rad/s)
error state dx = [dtheta, db]: q_true = dq(dtheta) (x) q, b_true = b + db       (6 x 1, cov. P)
propagate   omega = omega_meas - b;  q <- exp(omega h) (x) q   (triad.propagate, exact for a held rate)
            Phi = I + F h,  F = [[-[omega x], -I], [0, 0]]  (exp(F h) above 0.1 rad per step)
            P <- Phi P Phi^T + G Q G^T h,  Q = diag(sigma_v^2 I, sigma_u^2 I)
update      a unit vector measured in B, b_meas, of a known direction r in N:
            b_hat = A(q) r,  H = [[b_hat x], 0],  R = sigma^2 I
            K = P H^T (H P H^T + R)^-1,  dx = K (b_meas - b_hat)
            q <- normalize(q + 1/2 Xi(q) dtheta),  b <- b + db,  P <- (I - K H) P (I - K H)^T + K R K^T

sigma_v is the gyro's angle random walk (rad/s^0.5: the rate noise's spectral density), sigma_u
its bias random walk (rad/s^1.5). A gyro with white rate noise of standard deviation s per
sample at step h has sigma_v = s sqrt(h). With R = sigma^2 I the 3-vector update is the usual
approximation (the component along b_hat carries no information and H has no part there).
"""
from collections import deque
import math

import numpy as np

from ..core import rotations
from ..core import jit
from ..core.jit import njit
from ..environment.eclipse import sunlit_fraction
from . import triad
from .nadir_history import NadirHistory


# ---- the filter's matrix arithmetic (numba where installed: components.core.jit) ------------
# Written out element by element: for 6 x 6 matrices numpy's calls cost more than the arithmetic
# (the estimator runs at every 15 ms step of the mission). In plain Python the products are
# numpy's (the loops would be slower there); the two paths agree to rounding.

def _numpy_product(A, B, transpose_b):
    return A @ (B.T if transpose_b else B)


@njit(cache=True)
def _looped_product(A, B, transpose_b):
    """A B, or A B^T with transpose_b."""
    n, m = A.shape[0], B.shape[0] if transpose_b else B.shape[1]
    out = np.empty((n, m))
    for i in range(n):
        for j in range(m):
            total = 0.0
            for k in range(A.shape[1]):
                total += A[i, k] * (B[j, k] if transpose_b else B[k, j])
            out[i, j] = total
    return out


_product = _looped_product if jit.ENABLED else _numpy_product


# the angle per covariance step (rad) above which Phi is the exact transition: first order, Phi's
# attitude block is not a rotation, and P grows by about (1 + angle^2) per step (a body spun up
# by a thruster stuck open, hundreds of deg/s, overflowed it); the mission's nominal runs never
# come near (26 deg/s over 0.115 s is 0.05 rad), so they keep the first order bit for bit
EXACT_ANGLE = 0.1


@njit(cache=True)
def _propagated_covariance(P, w0, w1, w2, h, qv, qu):
    """Phi P Phi^T + Q h: Phi = I + F h, F = [[-[w x], -I], [0, 0]]; Q = diag(qv I, qu I) (G Q G^T = Q
    for G = diag(-I, I)). Above EXACT_ANGLE per step Phi = exp(F h) in closed form: the attitude
    block the rotation exp(-[w x] h), the bias block minus its integral over h (the tests compare
    it with scipy's expm)."""
    phi = np.eye(6)
    rate = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
    if rate * h <= EXACT_ANGLE:
        phi[0, 1], phi[0, 2], phi[1, 0] = w2 * h, -w1 * h, -w2 * h
        phi[1, 2], phi[2, 0], phi[2, 1] = w0 * h, w1 * h, -w0 * h
        for i in range(3):
            phi[i, i + 3] = -h
    else:
        angle = rate * h
        s, c = math.sin(angle), math.cos(angle)
        a, b, d = s / rate, (1.0 - c) / (rate * rate), (angle - s) / (rate * rate * rate)
        W = np.array([[0.0, -w2, w1], [w2, 0.0, -w0], [-w1, w0, 0.0]])  # [w x]
        W2 = W @ W
        for i in range(3):
            for j in range(3):
                eye = 1.0 if i == j else 0.0
                phi[i, j] = eye - a * W[i, j] + b * W2[i, j]
                phi[i, j + 3] = -h * eye + b * W[i, j] - d * W2[i, j]
    out = _product(_product(phi, P, False), phi, True)
    for i in range(3):
        out[i, i] += qv * h
        out[i + 3, i + 3] += qu * h
    return out


@njit(cache=True)
def _vector_update(P, b_hat, y, r, update_bias):
    """One vector measurement: H = [[b_hat x], 0], S = H P H^T + r I, K = P H^T S^-1, dx = K y,
    P <- (I - K H) P (I - K H)^T + r K K^T (Joseph form). Without update_bias the bias rows of K
    are zero: the bias is held, a consider state as in Schmidt's filter (the Joseph form holds for
    any gain, so P stays the covariance of the errors). Returns (P, dx, y^T S^-1 y)."""
    H = np.zeros((3, 6))
    H[0, 1], H[0, 2], H[1, 0] = -b_hat[2], b_hat[1], b_hat[2]
    H[1, 2], H[2, 0], H[2, 1] = -b_hat[0], -b_hat[1], b_hat[0]
    PHt = _product(P, H, True)
    S = _product(H, PHt, False)
    for i in range(3):
        S[i, i] += r
    # S^-1 from the adjugate (S is symmetric positive definite: r > 0)
    c00 = S[1, 1] * S[2, 2] - S[1, 2] * S[2, 1]
    c01 = S[1, 2] * S[2, 0] - S[1, 0] * S[2, 2]
    c02 = S[1, 0] * S[2, 1] - S[1, 1] * S[2, 0]
    det = S[0, 0] * c00 + S[0, 1] * c01 + S[0, 2] * c02
    S_inv = np.empty((3, 3))
    S_inv[0, 0], S_inv[1, 0], S_inv[2, 0] = c00 / det, c01 / det, c02 / det
    S_inv[0, 1] = (S[0, 2] * S[2, 1] - S[0, 1] * S[2, 2]) / det
    S_inv[1, 1] = (S[0, 0] * S[2, 2] - S[0, 2] * S[2, 0]) / det
    S_inv[2, 1] = (S[0, 1] * S[2, 0] - S[0, 0] * S[2, 1]) / det
    S_inv[0, 2] = (S[0, 1] * S[1, 2] - S[0, 2] * S[1, 1]) / det
    S_inv[1, 2] = (S[0, 2] * S[1, 0] - S[0, 0] * S[1, 2]) / det
    S_inv[2, 2] = (S[0, 0] * S[1, 1] - S[0, 1] * S[1, 0]) / det
    K = _product(PHt, S_inv, False)
    if not update_bias:
        for i in range(3, 6):
            for k in range(3):
                K[i, k] = 0.0
    dx = np.zeros(6)
    for i in range(6):
        for k in range(3):
            dx[i] += K[i, k] * y[k]
    nis = 0.0
    for i in range(3):
        for k in range(3):
            nis += y[i] * S_inv[i, k] * y[k]
    IKH = np.eye(6) - _product(K, H, False)
    P_new = _product(_product(IKH, P, False), IKH, True)
    KKt = _product(K, K, True)
    for i in range(6):
        for j in range(6):
            P_new[i, j] += r * KKt[i, j]
    return P_new, dx, nis


# ---- the estimator's state in one array, its step compiled ----------------------------------
# AttitudeEstimator keeps the state of its filters in one float array, each part a view its
# owner (AttitudeMEKF, RateFilter, NeesMonitor) reads and writes: the mission's step between two
# vector updates is then two compiled calls over arrays (_step_head, _step_tail; numba's call
# costs per argument, least for an array), and the updates stay in Python. Each kernel does the
# Python code's operations in the same order, so the estimates are the same bits.
# AttitudeMEKF's part: q_BN (4, scalar last), the bias (3), 1.0 once started, P's changes counted
Q, BIAS, STARTED, P_VERSION = 0, 4, 7, 8
MEKF_SIZE = 9
# RateFilter's part: the rate estimate (3), its variance per axis (3), the angular acceleration
# of the last prediction (3), 1.0 once the first sample came
RATE, RATE_VARIANCE, RATE_DOT, HAS_RATE = 0, 3, 6, 9
RATE_SIZE = 10
# NeesMonitor's part: steps counted, their NEES summed, those above NEES_BOUND_95, the last NEES
N_COUNT, N_TOTAL, N_OVER, N_LAST = 0, 1, 2, 3
NEES_SIZE = 4
# AttitudeEstimator's own part: the gyro sample held from the last step (3) and 1.0 once there is
# one, the covariance propagation gathered (its rate (3) and time), the time; per sensor the sample
# it gave at the last step (3) and 1.0 once it gave one, and the time of its last update
HELD, HAS_HELD, COV_RATE, COV_PENDING, TIME = 0, 3, 4, 7, 8
SEEN_NADIR, SEEN_SUN, SEEN_COARSE = 9, 13, 17
UPDATED_NADIR, UPDATED_SUN, UPDATED_COARSE = 21, 22, 23
SEEN = {"nadir": SEEN_NADIR, "sun": SEEN_SUN, "coarse": SEEN_COARSE}
UPDATED = {"nadir": UPDATED_NADIR, "sun": UPDATED_SUN, "coarse": UPDATED_COARSE}
ESTIMATOR_SIZE = 24
# where each part starts in AttitudeEstimator.x
AT_MEKF, AT_RATE, AT_NEES, AT_ESTIMATOR = 0, 9, 19, 23
STATE_SIZE = 47

# the packed inputs of a step (AttitudeEstimator.step_packed): the measurements and the truth
U_NADIR, U_NADIR_VALID, U_SUN, U_SUN_VALID, U_R_BN, U_R_SN, U_RATE, U_TORQUE = 0, 3, 4, 7, 8, 11, 14, 17
U_COARSE, U_COARSE_VALID, U_Q_TRUE, U_RATE_TRUE = 20, 23, 24, 28
U_SIZE = 31
# the step's constants (AttitudeEstimator._constants, per step size): h, (accel_sigma h)^2, the
# gyro sample's variance sigma_v^2 / h, the MEKF's sigma_v^2 and sigma_u^2, update_interval, 1.0
# with a coarse Sun sensor, the exponent 2.0 (a value: numba's x ** 2.0 with a constant exponent is
# x * x, which differs from Python's pow(x, 2.0) in the last bit now and then), J and J^-1 (9 each)
K_H, K_ACCEL_VARIANCE, K_SAMPLE_VARIANCE, K_QV, K_QU, K_INTERVAL, K_COARSE, K_TWO, K_J, K_J_INV = \
    0, 1, 2, 3, 4, 5, 6, 7, 8, 17
K_SIZE = 26
# the outputs (AttitudeEstimator.step_packed's y): q_BN (4), the rate (3), the angular acceleration
# (3), the attitude error and the rate error against the truth
Y_Q, Y_RATE, Y_RATE_DOT, Y_ATTITUDE_ERROR, Y_RATE_ERROR = 0, 4, 7, 10, 11
Y_SIZE = 12

# what _step_head returns besides the sensors due an update (1 nadir, 2 Sun, 4 coarse Sun)
RATE_NOT_FINITE, NO_ROTATION, NOT_STARTED = -1, -2, 8
# what _step_tail returns: 0 the outputs written (and the NEES recorded when asked)
TAIL_NOT_STARTED, TAIL_IN_PYTHON = 1, 2


@njit(cache=True)
def _normalized_quaternion(q0, q1, q2, q3):
    """(ok, q / |q|): rotations.normalized's operations, ok False where it raises."""
    n = math.sqrt(q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3)
    if not math.isfinite(n) or n < 1e-12:
        return False, q0, q1, q2, q3
    return True, q0 / n, q1 / n, q2 / n, q3 / n


@njit(cache=True)
def _circle_cross(p0, p1, p2, p3, q0, q1, q2, q3):
    """p (x) q: rotations.circle_cross's operations."""
    return (p3 * q0 + q3 * p0 - (p1 * q2 - p2 * q1),
            p3 * q1 + q3 * p1 - (p2 * q0 - p0 * q2),
            p3 * q2 + q3 * p2 - (p0 * q1 - p1 * q0),
            p3 * q3 - (p0 * q0 + p1 * q1 + p2 * q2))


@njit(cache=True)
def _propagated_attitude(q0, q1, q2, q3, w0, w1, w2, h):
    """(ok, q) rotated over h at the body rate w held (triad.propagate's operations in order:
    rotations.from_axis_angle, circle_cross, normalized); ok False where that raises."""
    wn = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
    if wn == 0.0 or h == 0.0:
        return _normalized_quaternion(q0, q1, q2, q3)
    n = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)  # from_axis_angle normalizes the axis
    if not math.isfinite(n) or n < 1e-12:
        return False, q0, q1, q2, q3
    e0, e1, e2 = w0 / n, w1 / n, w2 / n
    angle = wn * h
    s = math.sin(angle / 2.0)
    p0, p1, p2, p3 = e0 * s, e1 * s, e2 * s, math.cos(angle / 2.0)
    c0, c1, c2, c3 = _circle_cross(p0, p1, p2, p3, q0, q1, q2, q3)
    return _normalized_quaternion(c0, c1, c2, c3)


@njit(cache=True)
def _quadratic_form(a00, a10, a11, a20, a21, a22, d0, d1, d2):
    """d^T A^-1 d for a symmetric 3x3 A through its Cholesky factor L (A = L L^T: the value is
    |L^-1 d|^2); -1.0 when A is not positive definite."""
    if not a00 > 0.0:
        return -1.0
    l00 = math.sqrt(a00)
    l10, l20 = a10 / l00, a20 / l00
    p11 = a11 - l10 * l10
    if not p11 > 0.0:
        return -1.0
    l11 = math.sqrt(p11)
    l21 = (a21 - l20 * l10) / l11
    p22 = a22 - l20 * l20 - l21 * l21
    if not p22 > 0.0:
        return -1.0
    l22 = math.sqrt(p22)
    y0 = d0 / l00
    y1 = (d1 - l10 * y0) / l11
    y2 = (d2 - l20 * y0 - l21 * y1) / l22
    return y0 * y0 + y1 * y1 + y2 * y2


@njit(cache=True)
def _fused_vector_update(x, P, b0, b1, b2, r0, r1, r2, variance, update_bias):
    """AttitudeMEKF.update after its checks, in its state x and P (in place): the unit vector b
    measured of the reference direction r, b_hat = A(q) r (rotations.attitude_matrix), y = b - b_hat,
    _vector_update, q corrected by 1/2 Xi(q) dtheta (rotations.quaternion_rate) and normalized,
    the bias by db. Returns (ok, nis, y); ok False, with nothing changed, when the corrected q has
    no norm."""
    q1, q2, q3, q4 = x[Q], x[Q + 1], x[Q + 2], x[Q + 3]
    b_hat = np.empty(3)
    b_hat[0] = (q1 * q1 - q2 * q2 - q3 * q3 + q4 * q4) * r0 + 2 * (q1 * q2 + q3 * q4) * r1 \
        + 2 * (q1 * q3 - q2 * q4) * r2
    b_hat[1] = 2 * (q1 * q2 - q3 * q4) * r0 + (-q1 * q1 + q2 * q2 - q3 * q3 + q4 * q4) * r1 \
        + 2 * (q2 * q3 + q1 * q4) * r2
    b_hat[2] = 2 * (q1 * q3 + q2 * q4) * r0 + 2 * (q2 * q3 - q1 * q4) * r1 \
        + (-q1 * q1 - q2 * q2 + q3 * q3 + q4 * q4) * r2
    y = np.empty(3)
    y[0], y[1], y[2] = b0 - b_hat[0], b1 - b_hat[1], b2 - b_hat[2]
    P_new, dx, nis = _vector_update(P, b_hat, y, variance, update_bias)
    d1, d2, d3, d4 = rotations.quaternion_rate_kernel(q1, q2, q3, q4, dx[0], dx[1], dx[2])
    ok, n0, n1, n2, n3 = _normalized_quaternion(q1 + d1, q2 + d2, q3 + d3, q4 + d4)
    if not ok:
        return False, nis, y
    P[:, :] = P_new
    x[P_VERSION] += 1.0
    x[Q], x[Q + 1], x[Q + 2], x[Q + 3] = n0, n1, n2, n3
    for i in range(3):
        x[BIAS + i] = x[BIAS + i] + dx[3 + i]
    return True, nis, y


@njit(cache=True)
def _rate_predict(r, k, t0, t1, t2):
    """RateFilter.predict on its state r: J omega_dot = L - omega x J omega over the step."""
    if r[HAS_RATE] == 0.0:
        return
    J, Ji = K_J, K_J_INV
    w0, w1, w2 = r[RATE], r[RATE + 1], r[RATE + 2]
    j0 = k[J] * w0 + k[J + 1] * w1 + k[J + 2] * w2
    j1 = k[J + 3] * w0 + k[J + 4] * w1 + k[J + 5] * w2
    j2 = k[J + 6] * w0 + k[J + 7] * w1 + k[J + 8] * w2
    v0 = t0 - (w1 * j2 - w2 * j1)
    v1 = t1 - (w2 * j0 - w0 * j2)
    v2 = t2 - (w0 * j1 - w1 * j0)
    a0 = k[Ji] * v0 + k[Ji + 1] * v1 + k[Ji + 2] * v2
    a1 = k[Ji + 3] * v0 + k[Ji + 4] * v1 + k[Ji + 5] * v2
    a2 = k[Ji + 6] * v0 + k[Ji + 7] * v1 + k[Ji + 8] * v2
    h, q = k[K_H], k[K_ACCEL_VARIANCE]
    r[RATE_DOT], r[RATE_DOT + 1], r[RATE_DOT + 2] = a0, a1, a2
    r[RATE], r[RATE + 1], r[RATE + 2] = w0 + a0 * h, w1 + a1 * h, w2 + a2 * h
    for i in range(3):
        r[RATE_VARIANCE + i] = r[RATE_VARIANCE + i] + q


@njit(cache=True)
def _rate_update(r, k, z0, z1, z2):
    """RateFilter.update on its state r with one bias-corrected gyro sample z."""
    R = k[K_SAMPLE_VARIANCE]
    if r[HAS_RATE] == 0.0:
        r[RATE], r[RATE + 1], r[RATE + 2] = z0, z1, z2
        r[RATE_VARIANCE], r[RATE_VARIANCE + 1], r[RATE_VARIANCE + 2] = R, R, R
        r[HAS_RATE] = 1.0
        return
    for i, z in enumerate((z0, z1, z2)):
        p = r[RATE_VARIANCE + i]
        gain = p / (p + R)
        r[RATE + i] += gain * (z - r[RATE + i])
        r[RATE_VARIANCE + i] = p * (1.0 - gain)


@njit(cache=True)
def _nees_add(n, nees):
    """NeesMonitor.add on its state n."""
    n[N_COUNT] += 1.0
    n[N_TOTAL] += nees
    if nees > NEES_BOUND_95:
        n[N_OVER] += 1.0
    n[N_LAST] = nees


@njit(cache=True)
def _arrived(x, u, at, seen, updated, interval):
    """AttitudeEstimator._new in x: the sample u[at:at + 3] differs from the one this sensor gave
    at the last step (kept now) and the update interval has passed since its last update."""
    arrived = x[seen + 3] == 0.0 or u[at] != x[seen] or u[at + 1] != x[seen + 1] or u[at + 2] != x[seen + 2]
    x[seen], x[seen + 1], x[seen + 2], x[seen + 3] = u[at], u[at + 1], u[at + 2], 1.0
    return arrived and x[TIME] - x[updated] >= interval - 1e-9


@njit(cache=True)
def _step_head(x, P, u, k):
    """AttitudeEstimator.step up to its vector updates, in x (P changed in place): the attitude
    propagated with the mean gyro rate, the rate filter's prediction, and, once started, which
    sensors give a new sample to use (the returned bits: 1 nadir, 2 Sun, 4 coarse Sun) with the
    covariance propagated before them or once COVARIANCE_STEP has gathered. NOT_STARTED before
    the first fix (the Python code takes it from there); RATE_NOT_FINITE or NO_ROTATION, with
    nothing but the time changed, where the Python code raises."""
    m, e, h = AT_MEKF, AT_ESTIMATOR, k[K_H]
    x[e + TIME] += h
    started = x[m + STARTED] != 0.0
    if started and x[e + HAS_HELD] != 0.0:
        w0 = 0.5 * (x[e + HELD] + u[U_RATE]) - x[m + BIAS]
        w1 = 0.5 * (x[e + HELD + 1] + u[U_RATE + 1]) - x[m + BIAS + 1]
        w2 = 0.5 * (x[e + HELD + 2] + u[U_RATE + 2]) - x[m + BIAS + 2]
        if not (math.isfinite(w0) and math.isfinite(w1) and math.isfinite(w2)):
            return RATE_NOT_FINITE
        ok, q0, q1, q2, q3 = _propagated_attitude(x[m + Q], x[m + Q + 1], x[m + Q + 2], x[m + Q + 3], w0, w1, w2, h)
        if not ok:
            return NO_ROTATION
        x[m + Q], x[m + Q + 1], x[m + Q + 2], x[m + Q + 3] = q0, q1, q2, q3
        x[e + COV_PENDING] += h
        x[e + COV_RATE], x[e + COV_RATE + 1], x[e + COV_RATE + 2] = w0, w1, w2
    _rate_predict(x[AT_RATE:AT_RATE + RATE_SIZE], k, u[U_TORQUE], u[U_TORQUE + 1], u[U_TORQUE + 2])
    if not started:
        return NOT_STARTED
    due = 0
    interval = k[K_INTERVAL]
    if u[U_NADIR_VALID] != 0.0 and _arrived(x[e:], u, U_NADIR, SEEN_NADIR, UPDATED_NADIR, interval):
        due |= 1
    if u[U_SUN_VALID] != 0.0:
        if _arrived(x[e:], u, U_SUN, SEEN_SUN, UPDATED_SUN, interval):
            due |= 2
    elif k[K_COARSE] != 0.0 and u[U_COARSE_VALID] != 0.0 and _arrived(x[e:], u, U_COARSE, SEEN_COARSE,
                                                                        UPDATED_COARSE, interval):
        due |= 4
    if (due or x[e + COV_PENDING] >= COVARIANCE_STEP - 1e-9) and x[e + COV_PENDING] > 0.0:
        P[:, :] = _propagated_covariance(P, x[e + COV_RATE], x[e + COV_RATE + 1], x[e + COV_RATE + 2],
                                         x[e + COV_PENDING], k[K_QV], k[K_QU])
        x[e + COV_PENDING] = 0.0
        x[m + P_VERSION] += 1.0
    return due


@njit(cache=True)
def _step_tail(x, P, u, k, y, check):
    """AttitudeEstimator.step after its vector updates (the gyro sample held, the rate filter's
    update), then with `check` AttitudeEstimator.check against the true attitude, and the
    outputs in y (the wrapper's: the estimate, the rate and the acceleration, the errors against
    the truth). TAIL_NOT_STARTED before the first fix and TAIL_IN_PYTHON where the NEES needs
    the Python code (an attitude block not positive definite, a true attitude of zero norm), both
    after the rate filter's update, with neither the NEES recorded nor y written."""
    m, e = AT_MEKF, AT_ESTIMATOR
    x[e + HELD], x[e + HELD + 1], x[e + HELD + 2], x[e + HAS_HELD] = u[U_RATE], u[U_RATE + 1], u[U_RATE + 2], 1.0
    _rate_update(x[AT_RATE:AT_RATE + RATE_SIZE], k, u[U_RATE] - x[m + BIAS], u[U_RATE + 1] - x[m + BIAS + 1],
                 u[U_RATE + 2] - x[m + BIAS + 2])
    if x[m + STARTED] == 0.0:
        return TAIL_NOT_STARTED
    q0, q1, q2, q3 = x[m + Q], x[m + Q + 1], x[m + Q + 2], x[m + Q + 3]
    ok_true, t0, t1, t2, t3 = _normalized_quaternion(u[U_Q_TRUE], u[U_Q_TRUE + 1], u[U_Q_TRUE + 2], u[U_Q_TRUE + 3])
    ok, p0, p1, p2, p3 = _normalized_quaternion(q0, q1, q2, q3)
    if not (ok_true and ok):
        return TAIL_IN_PYTHON
    if check:  # attitude_nees: the error rotation q_true (x) conjugate(q), as twice its vector part
        e0, e1, e2, e3 = _circle_cross(t0, t1, t2, t3, -q0, -q1, -q2, q3)
        sign = 2.0 if e3 >= 0.0 else -2.0
        nees = _quadratic_form(P[0, 0], P[1, 0], P[1, 1], P[2, 0], P[2, 1], P[2, 2], e0 * sign, e1 * sign,
                               e2 * sign)
        if nees < 0.0:
            return TAIL_IN_PYTHON
        _nees_add(x[AT_NEES:AT_NEES + NEES_SIZE], nees)
    r = AT_RATE
    w0, w1, w2 = x[r + RATE], x[r + RATE + 1], x[r + RATE + 2]
    y[Y_Q], y[Y_Q + 1], y[Y_Q + 2], y[Y_Q + 3] = q0, q1, q2, q3
    y[Y_RATE], y[Y_RATE + 1], y[Y_RATE + 2] = w0, w1, w2
    y[Y_RATE_DOT], y[Y_RATE_DOT + 1], y[Y_RATE_DOT + 2] = x[r + RATE_DOT], x[r + RATE_DOT + 1], x[r + RATE_DOT + 2]
    # triad.error_angle(q, q_true): 2 atan2(|e_v|, |e_4|) of normalized(q) (x) conjugate(normalized(q_true))
    e0, e1, e2, e3 = _circle_cross(p0, p1, p2, p3, -t0, -t1, -t2, t3)
    y[Y_ATTITUDE_ERROR] = 2.0 * math.atan2(math.sqrt(e0 * e0 + e1 * e1 + e2 * e2), abs(e3))
    two = k[K_TWO]
    total = 0.0
    total += (w0 - u[U_RATE_TRUE]) ** two
    total += (w1 - u[U_RATE_TRUE + 1]) ** two
    total += (w2 - u[U_RATE_TRUE + 2]) ** two
    y[Y_RATE_ERROR] = math.sqrt(total)
    return 0


def _sigma(name, value, unit, positive=False):
    value = float(value)
    if not (math.isfinite(value) and (value > 0.0 if positive else value >= 0.0)):
        raise ValueError(f"{name} = {value!r} must be a finite number {'>' if positive else '>='} 0 ({unit})")
    return value


class AttitudeMEKF:
    """sigma_v (rad/s^0.5), sigma_u (rad/s^1.5); initialize() before the first propagate/update.
    The state (q, the bias) lives in `state` (MEKF_SIZE floats; AttitudeEstimator gives a view of
    its own array), the covariance in P."""

    def __init__(self, sigma_v=5.5e-4 * math.sqrt(0.1), sigma_u=1e-6, state=None):
        self.sigma_v = _sigma("sigma_v", sigma_v, "rad/s^0.5")
        self.sigma_u = _sigma("sigma_u", sigma_u, "rad/s^1.5")
        self._x = np.zeros(MEKF_SIZE) if state is None else state
        self._x[:] = 0.0
        self._P = None
        self._block, self._block_of = None, -1.0  # P's attitude block as lists, and the P_VERSION it is of

    @property
    def initialized(self):
        return bool(self._x[STARTED] != 0.0)

    @property
    def q(self):
        """q_BN (scalar last) as a tuple of floats; None before initialize()."""
        x = self._x
        return tuple(x[Q:Q + 4].tolist()) if x[STARTED] != 0.0 else None

    @q.setter
    def q(self, value):
        if value is None:
            self._x[STARTED] = 0.0
        else:
            self._x[Q:Q + 4] = value
            self._x[STARTED] = 1.0

    @property
    def bias(self):
        """The gyro bias estimate (rad/s), an array (a copy)."""
        return self._x[BIAS:BIAS + 3].copy()

    @bias.setter
    def bias(self, value):
        self._x[BIAS:BIAS + 3] = value

    @property
    def P(self):
        """The error state's covariance (6 x 6, attitude then bias), None before initialize()."""
        return self._P

    @P.setter
    def P(self, value):
        self._P = None if value is None else np.ascontiguousarray(value, dtype=float)
        self._x[P_VERSION] += 1.0

    def _attitude_block(self):
        """P's attitude block as nested lists, kept while P is unchanged (the NEES and the sigmas
        read it at every step; P changes at covariance propagations and updates)."""
        version = self._x[P_VERSION]
        if self._block_of != version:
            self._block, self._block_of = self._P[:3, :3].tolist(), version
        return self._block

    def initialize(self, q, sigma_attitude, bias=(0.0, 0.0, 0.0), sigma_bias=1e-3):
        """Start from q (e.g. a TRIAD fix) with 1-sigma errors sigma_attitude (rad) per axis and
        sigma_bias (rad/s) on the bias."""
        q = rotations.normalized(tuple(float(x) for x in q), "q")
        b = np.array([float(x) for x in bias])
        if b.shape != (3,) or not np.all(np.isfinite(b)):
            raise ValueError(f"bias {list(bias)} must be three finite numbers (rad/s)")
        sa = _sigma("sigma_attitude", sigma_attitude, "rad", positive=True)
        sb = _sigma("sigma_bias", sigma_bias, "rad/s", positive=True)
        self.q, self.bias = q, b
        self.P = np.diag([sa * sa] * 3 + [sb * sb] * 3)

    def _need(self):
        if not self.initialized:
            raise ValueError("the filter is not initialized (no attitude fix yet)")

    def rate(self, omega_meas):
        """The rate estimate omega_meas - b (rad/s)."""
        b = self._x[BIAS:BIAS + 3].tolist()
        return (float(omega_meas[0]) - b[0], float(omega_meas[1]) - b[1], float(omega_meas[2]) - b[2])

    def propagate(self, omega_meas, h, covariance=True):
        """Attitude over h with the bias-corrected rate held; the covariance too unless the
        caller gathers several steps into one propagate_covariance (first order up to EXACT_ANGLE)."""
        self._need()
        w = self.rate(omega_meas)
        if not (math.isfinite(w[0]) and math.isfinite(w[1]) and math.isfinite(w[2])):
            raise ValueError(f"omega_meas_B {list(omega_meas)} must be finite")
        ok, *q = _propagated_attitude(*self._x[Q:Q + 4].tolist(), w[0], w[1], w[2], float(h))
        # not ok: a rate too small to give a rotation axis, which triad.propagate says
        self.q = q if ok else triad.propagate(self.q, w, h)
        if covariance:
            self.propagate_covariance(w, h)

    def propagate_covariance(self, w, h):
        """P over h with the (bias-corrected) rate w: Phi = I + F h."""
        self.P = _propagated_covariance(self.P, float(w[0]), float(w[1]), float(w[2]), float(h),
                                        self.sigma_v ** 2, self.sigma_u ** 2)

    def update(self, b_meas, r_ref, sigma, update_bias=True):
        """Fuse one measured unit vector b_meas (B) of the reference direction r_ref (N). Returns
        (normalized innovation squared y^T S^-1 y, |y|^2) of the update, y = b_meas - b_hat.
        Without update_bias the bias estimate is held (a consider state) and only the attitude
        is corrected; the covariance stays that of the errors, the bias' growing by its random walk."""
        self._need()
        b = triad._unit(b_meas, "measured vector")
        r = triad._unit(r_ref, "reference vector")
        s = _sigma("measurement sigma", sigma, "rad", positive=True)
        ok, nis, y = _fused_vector_update(self._x, self._P, b[0], b[1], b[2], r[0], r[1], r[2], s * s,
                                          bool(update_bias))
        if not ok:
            raise ValueError(f"the attitude corrected by the {list(b)} measurement has zero or non-finite norm: the "
                             "filter diverged")
        return float(nis), float(y @ y)

    def reopen_bias(self, sigma_bias, attitude_variance=0.0):
        """Forget what the filter learned of the bias (a fault changed it): its covariance back to
        sigma_bias (rad/s) per axis, uncorrelated with the attitude, whose variance per axis grows
        by attitude_variance (rad^2), the error the wrong bias has left."""
        self._need()
        sb = _sigma("sigma_bias", sigma_bias, "rad/s", positive=True)
        self.P[3:, :] = 0.0
        self.P[:, 3:] = 0.0
        self.P[3:, 3:] = np.eye(3) * sb * sb
        self.P[:3, :3] += np.eye(3) * _sigma("attitude_variance", attitude_variance, "rad^2")
        self._x[P_VERSION] += 1.0  # changed in place

    def attitude_sigma(self):
        """1-sigma attitude errors (rad) about the body axes: sqrt of the diagonal of P."""
        self._need()
        A = self._attitude_block()
        return (math.sqrt(max(0.0, A[0][0])), math.sqrt(max(0.0, A[1][1])), math.sqrt(max(0.0, A[2][2])))

    def attitude_nees(self, q_true):
        """Normalized estimation error squared of the attitude against the true q:
        dtheta^T P_aa^-1 dtheta, dtheta the small rotation (body axes) that takes the estimate to
        q_true, as the filter defines its error (q_true = dq(dtheta) (x) q). Chi-square with 3
        degrees of freedom when the covariance is consistent: mean 3, above NEES_BOUND_95 one
        time in twenty."""
        self._need()
        e = rotations.circle_cross(rotations.normalized((float(q_true[0]), float(q_true[1]), float(q_true[2]),
                                                         float(q_true[3])), "q_true"), rotations.conjugate(self.q))
        k = 2.0 if e[3] >= 0.0 else -2.0
        d = (e[0] * k, e[1] * k, e[2] * k)
        nees = _inverse_quadratic_form(self._attitude_block(), d)
        if nees is None:  # the attitude block is not positive definite: a filter gone wrong, LU then
            nees = float(np.array(d) @ np.linalg.solve(self.P[:3, :3], np.array(d)))
        return nees

    def bias_sigma(self):
        self._need()
        return tuple(float(math.sqrt(max(0.0, self.P[i, i]))) for i in range(3, 6))

    def get_state(self):
        return {"q": None if self.q is None else list(self.q), "bias": self.bias.tolist(),
                "P": None if self.P is None else self.P.tolist()}

    def set_state(self, state):
        self.q = None if state["q"] is None else tuple(state["q"])
        self.bias = np.array(state["bias"], dtype=float)
        self.P = None if state["P"] is None else np.array(state["P"], dtype=float)


def _inverse_quadratic_form(A, d):
    """d^T A^-1 d for a symmetric positive definite 3x3 A (nested lists) through its Cholesky
    factor (_quadratic_form): at every step of the mission numpy's solve costs ten times more in
    its call overhead than in the arithmetic. None when A is not positive definite."""
    value = _quadratic_form(float(A[0][0]), float(A[1][0]), float(A[1][1]), float(A[2][0]), float(A[2][1]),
                            float(A[2][2]), float(d[0]), float(d[1]), float(d[2]))
    return None if value < 0.0 else value


class RateFilter:
    """Body-rate estimate for the controllers: per axis a Kalman filter whose prediction is Euler's
    equation with the commanded torque, J omega_dot = L - omega x J omega, and whose measurement
    is the bias-corrected gyro rate (variance sigma_v^2 / h per sample at step h). The torque
    model carries the estimate through a firing without the lag of a plain low-pass filter;
    `accel_sigma` (rad/s^2, the 1-sigma unmodelled angular acceleration: thruster force and
    direction errors, disturbances) sets how much the gyro is trusted over the model.
    The state lives in `state` (RATE_SIZE floats; AttitudeEstimator gives a view of its array)."""

    def __init__(self, inertia, sigma_v, accel_sigma, state=None):
        J = np.array(inertia, dtype=float).reshape(3, 3)
        if not np.all(np.isfinite(J)) or np.any(np.linalg.eigvalsh(0.5 * (J + J.T)) <= 0.0):
            raise ValueError(f"inertia {J.tolist()} must be finite and positive definite (kg.m2)")
        self.J, self.J_inv = J.tolist(), np.linalg.inv(J).tolist()
        self.sigma_v = _sigma("sigma_v", sigma_v, "rad/s^0.5")
        self.accel_sigma = _sigma("rate accel_sigma", accel_sigma, "rad/s^2")
        self._x = np.zeros(RATE_SIZE) if state is None else state
        self._x[:] = 0.0  # no estimate before the first sample
        self._k = np.zeros(K_SIZE)  # the constants of its kernels (step_constants)
        self._k[K_J:K_J + 9], self._k[K_J_INV:K_J_INV + 9] = J.ravel(), np.ravel(self.J_inv)

    def step_constants(self, k, h):
        """Fill this filter's part of the constants `k` of a step of h seconds."""
        k[K_H] = h
        k[K_ACCEL_VARIANCE] = (self.accel_sigma * h) ** 2
        k[K_SAMPLE_VARIANCE] = self.sigma_v ** 2 / max(h, 1e-9)

    @property
    def omega(self):
        """The rate estimate (rad/s) as a list; None before the first sample."""
        return self._x[RATE:RATE + 3].tolist() if self._x[HAS_RATE] != 0.0 else None

    @property
    def P(self):
        """The estimate's variance per axis."""
        return self._x[RATE_VARIANCE:RATE_VARIANCE + 3].tolist()

    @property
    def omega_dot(self):
        """The angular acceleration of the last prediction (rad/s^2)."""
        return tuple(self._x[RATE_DOT:RATE_DOT + 3].tolist())

    def predict(self, torque, h):
        """Carry the estimate over a step of h seconds with the torque commanded over it."""
        self.step_constants(self._k, float(h))
        _rate_predict(self._x, self._k, float(torque[0]), float(torque[1]), float(torque[2]))

    def update(self, omega_corrected, h):
        """Fuse one bias-corrected gyro sample taken at the end of a step of h seconds."""
        self.step_constants(self._k, float(h))
        _rate_update(self._x, self._k, float(omega_corrected[0]), float(omega_corrected[1]),
                     float(omega_corrected[2]))

    def get_state(self):
        return {"omega": self.omega, "P": self.P, "omega_dot": list(self.omega_dot)}

    def set_state(self, state):
        x = self._x
        x[HAS_RATE] = 0.0 if state["omega"] is None else 1.0
        if state["omega"] is not None:
            x[RATE:RATE + 3] = [float(v) for v in state["omega"]]
        x[RATE_VARIANCE:RATE_VARIANCE + 3] = [float(v) for v in state["P"]]
        x[RATE_DOT:RATE_DOT + 3] = [float(v) for v in state["omega_dot"]]


# 95 % quantile of the chi-square distribution with 3 degrees of freedom (scipy.stats.chi2.ppf(0.95, 3))
NEES_BOUND_95 = 7.814727903251178


class NeesMonitor:
    """The attitude NEES over the steps it is given: its mean (3 when the covariance is
    consistent) and the share of steps above NEES_BOUND_95 (0.05 when consistent). The counts
    live in `state` (NEES_SIZE floats; AttitudeEstimator gives a view of its array)."""

    def __init__(self, state=None):
        self._x = np.zeros(NEES_SIZE) if state is None else state
        self._x[:] = 0.0

    @property
    def count(self):
        return int(self._x[N_COUNT])

    @property
    def total(self):
        return float(self._x[N_TOTAL])

    @property
    def over(self):
        return int(self._x[N_OVER])

    @property
    def last(self):
        return float(self._x[N_LAST])

    def add(self, nees):
        _nees_add(self._x, float(nees))

    @property
    def mean(self):
        count = self._x[N_COUNT]
        return float(self._x[N_TOTAL] / count) if count else 0.0

    @property
    def over_fraction(self):
        count = self._x[N_COUNT]
        return float(self._x[N_OVER] / count) if count else 0.0

    def get_state(self):
        return {"count": self.count, "total": self.total, "over": self.over, "last": self.last}

    def set_state(self, state):
        self._x[:] = (int(state["count"]), float(state["total"]), int(state["over"]), float(state["last"]))


# The estimator propagates the covariance in steps of at least this long (and before each
# update): at the 15 ms attitude loop, the 6 x 6 products are most of the filter's cost.
COVARIANCE_STEP = 0.1


# The horizon sensor's history before a fix is let go once it spans this many nadir_history_time
# (an eclipse of up to 36 minutes and the minutes of sunlight that tell the Sun sensors failed fit)
HISTORY_KEPT = 3.0

BIAS_LEARNED = 0.2  # of sigma_bias0: the fault monitor watches once every axis' bias sigma is below it


class InnovationMonitor:
    """Fault detection from the filter's own innovations (a gyro bias that jumps): the mean of the
    normalized innovation squared (NIS, y^T S^-1 y) over the last `window` vector updates. A
    sensor's error here is a rotation of N(0, sigma) about a random axis across the vector, so a
    consistent filter's NIS is 2 chi-square(1) (mean 2; a Gaussian error per axis would give the
    lighter-tailed chi-square(2)), and the mean of 100 of them exceeds `limit` = 3.64 with
    probability 1e-6. A mean above the limit is a model the data contradict: the estimator then
    reopens the bias (AttitudeMEKF.reopen_bias) and starts a new window. window 0: off."""

    def __init__(self, window=0, limit=3.64):
        if isinstance(window, bool) or int(window) != window or int(window) < 0:
            raise ValueError(f"fault window = {window!r} must be an integer >= 0 (vector updates; 0: off)")
        self.window = int(window)
        self.limit = _sigma("fault limit", limit, "mean NIS", positive=True)
        self.restart()
        self.detections = 0
        self.largest = 0.0  # the largest window mean seen (how close nominal flight comes to the limit)

    def add(self, nis, squared, armed=True):
        """Record one update; True when armed and the window's mean is above the limit (a
        detection)."""
        if not self.window:
            return False
        self.nis.append(nis)
        self.squared.append(squared)
        if len(self.nis) < self.window or not armed:
            return False
        mean = sum(self.nis) / self.window
        self.largest = max(self.largest, mean)
        if mean <= self.limit:
            return False
        self.detections += 1
        return True

    def error_variance(self):
        """The mean |y|^2 / 2 over the window (rad^2 per axis): the attitude error behind it."""
        return 0.5 * sum(self.squared) / max(1, len(self.squared))

    def restart(self):
        self.nis, self.squared = deque(maxlen=self.window), deque(maxlen=self.window)

    def get_state(self):
        return {"nis": list(self.nis), "squared": list(self.squared), "detections": self.detections,
                "largest": self.largest}

    def set_state(self, state):
        self.restart()
        self.nis.extend(state["nis"])
        self.squared.extend(state["squared"])
        self.detections, self.largest = int(state["detections"]), float(state["largest"])


class AttitudeEstimator:
    """TRIAD to start, then the MEKF (thesis section 3.3.1), and the rate filter: the estimator
    the controllers fly on.

    step(measurements, omega_meas, h, torque) once per communication point, with the
    measurements taken now, at the end of the step of h seconds just ended, and the torque
    commanded over that step:
    1. the attitude is propagated over the step with the mean of the gyro samples at its start
       (held) and end (second order: a tumbling body's rate changes within a step), the rate
       estimate with the torque (RateFilter.predict);
    2. before the first fix, TRIAD is tried (triad.AttitudeDetermination.fix) and, when possible,
       starts the filter with its first-order error; afterwards each vector that is a new sample
       (it differs from the one used last, and `update_interval` has passed since) updates the
       filter (no Sun vector in eclipse or outside the sensor's field of view);
       with `coarse_sun_sigma` set, a coarse Sun vector (e.g. coarse sun sensors on every face)
       stands in for the fine one whenever the fine sensor does not see the Sun, in the fix and
       in the updates: on a tumbling host one narrow-field sensor may never see it;
    3. the gyro sample of now corrects the rate estimate and is held for the next step.
    With `fault_window` > 0 the innovations are watched (InnovationMonitor): when the data
    contradict the filter, the bias is reopened to sigma_bias0 and learned again (`innovations.detections`).
    So the estimate refers to the time of the measurements: the end of the step when the
    sensors were read after the truth advanced (a Gauss-Seidel master with the estimator after
    the rigid body and the sensors), its start otherwise (one step of latency)."""

    def __init__(self, nadir_sigma=math.radians(0.25), sun_sigma=math.radians(0.5) / 3.0,
                 sigma_v=5.5e-4 * math.sqrt(0.1), sigma_u=1e-6, sigma_bias0=1e-3, min_separation=math.radians(5.0),
                 inertia=None, accel_sigma=5e-4, update_interval=0.0, coarse_sun_sigma=None, fault_window=0,
                 fault_limit=3.64, nadir_history_time=0.0, sun_missing_time=300.0, history_fix_sigma=0.0):
        self.triad = triad.AttitudeDetermination(nadir_sigma, sun_sigma, min_separation=min_separation)
        self.coarse_triad = None if coarse_sun_sigma is None else \
            triad.AttitudeDetermination(nadir_sigma, coarse_sun_sigma, min_separation=min_separation)
        self.x = np.zeros(STATE_SIZE)  # the state of the filters and the estimator's own (AT_*)
        self._e = self.x[AT_ESTIMATOR:]
        self.filter = AttitudeMEKF(sigma_v, sigma_u, state=self.x[AT_MEKF:AT_MEKF + MEKF_SIZE])
        self.rates = RateFilter(np.diag([0.05, 0.1, 0.1]) if inertia is None else inertia, sigma_v, accel_sigma,
                                state=self.x[AT_RATE:AT_RATE + RATE_SIZE])
        self.sigma_bias0 = _sigma("sigma_bias0", sigma_bias0, "rad/s", positive=True)
        self.update_interval = _sigma("update_interval", update_interval, "s")
        # per-axis sigmas of the vector measurements (the sensors' error angle RMS over two axes)
        self.nadir_sigma = max(self.triad.nadir_sigma, 1e-6) / math.sqrt(2.0)
        self.sun_sigma = max(self.triad.sun_sigma, 1e-6) / math.sqrt(2.0)
        self.coarse_sigma = None if coarse_sun_sigma is None else \
            max(self.coarse_triad.sun_sigma, 1e-6) / math.sqrt(2.0)
        for name in UPDATED:  # no update yet from any sensor
            self._e[UPDATED[name]] = -math.inf
        self.consistency = NeesMonitor(state=self.x[AT_NEES:AT_NEES + NEES_SIZE])  # against the truth (check)
        self.innovations = InnovationMonitor(fault_window, fault_limit)
        self._u = np.zeros(U_SIZE)  # step()'s packed inputs
        self._y = np.zeros(Y_SIZE)  # step_packed's outputs when the caller gives none
        self._k, self._k_h = np.zeros(K_SIZE), None  # the step's constants, and the step size they are for
        # without a Sun vector: the fix from the horizon sensor's history (nadir_history.py)
        self.nadir_history_time = _sigma("nadir_history_time", nadir_history_time, "s")
        self.sun_missing_time = _sigma("sun_missing_time", sun_missing_time, "s")
        # the history's fix is taken once its largest 1-sigma is this or less (0: any): in a weak
        # geometry a longer arc narrows it (nadir_history.py)
        self.history_fix_sigma = _sigma("history_fix_sigma", history_fix_sigma, "rad")
        self.history = NadirHistory(self.triad.nadir_sigma, self.sigma_bias0) \
            if self.nadir_history_time > 0.0 else None
        self.sunlit_without_sun = 0.0  # s in sunlight with no Sun vector, before the first fix
        self.without_sun = False  # the filter started from the history and has had no Sun vector since
        # ... and its gyro bias is held since (a consider state): in the burn the body turns with
        # the orbit, about the orbit normal at the orbital rate, and the nadir is the only vector; a
        # bias along the track (normal to the nadir in the orbit plane) then drifts the nadir as a
        # rotation about the nadir of bias / orbital rate does (gyrocompassing): the data cannot
        # tell the two apart. The filter moved along that combination anyway (525 km run 28: its
        # bias along x walked 0.011 deg/s, 11 deg about the nadir by the end of a 118 min burn, 5
        # sigma). So the bias stays what the history's fix learned over the tumble, its covariance
        # growing by the random walk the filter assumes, until a Sun vector comes or the bias is
        # reopened. Holding only its part along the track did no better in the campaigns' runs
        # without the Sun (docs/models/sensing.md).
        self.bias_held = False

    @property
    def rate(self):
        """The rate estimate (rad/s, body axes); None before the first gyro sample."""
        w = self.rates.omega
        return None if w is None else (float(w[0]), float(w[1]), float(w[2]))

    @property
    def acceleration(self):
        """The angular acceleration over the last step (rad/s^2) from the commanded torque."""
        return tuple(self.rates.omega_dot)

    @property
    def time(self):
        """The time of the step's end (s) since the estimator started."""
        return float(self._e[TIME])

    @property
    def held_rate(self):
        """The gyro sample of the step's start (rad/s); None before the first step."""
        e = self._e
        return tuple(e[HELD:HELD + 3].tolist()) if e[HAS_HELD] != 0.0 else None

    @property
    def cov_pending(self):
        """The time (s) gathered for the next covariance propagation."""
        return float(self._e[COV_PENDING])

    @property
    def cov_rate(self):
        """The rate (rad/s) the gathered covariance propagation takes."""
        return tuple(self._e[COV_RATE:COV_RATE + 3].tolist())

    def _new(self, name, vector):
        """A sample to use now: it has just arrived (it differs from the one this sensor gave at
        the last step) and update_interval has passed since the last update from this sensor. A
        sample that arrives sooner is dropped, not kept for later: used later it would be older
        than the estimate it corrects (a held sample 6 steps late is 1.5 deg off at 17 deg/s).
        (_arrived, in the compiled step, is the same test.)"""
        e, at = self._e, SEEN[name]
        vector = [float(v) for v in vector]
        arrived = e[at + 3] == 0.0 or vector != e[at:at + 3].tolist()
        e[at:at + 3], e[at + 3] = vector, 1.0
        return arrived and e[TIME] - e[UPDATED[name]] >= self.update_interval - 1e-9

    def _mark(self, name, vector):
        e, at = self._e, SEEN[name]
        e[UPDATED[name]] = e[TIME]
        e[at:at + 3], e[at + 3] = [float(v) for v in vector], 1.0

    def step(self, measurements, omega_meas, h, torque=(0.0, 0.0, 0.0), coarse_sun=None):
        """measurements = (nadir_B, nadir_valid, sun_B, sun_valid, r_BN_N, r_SN_N);
        coarse_sun = (sun_B, valid) of the coarse sensors, used only with coarse_sun_sigma."""
        nadir_B, nadir_valid, sun_B, sun_valid, r_BN_N, r_SN_N = measurements
        u = self._u
        u[U_NADIR:U_NADIR + 3], u[U_NADIR_VALID] = nadir_B, bool(nadir_valid)
        u[U_SUN:U_SUN + 3], u[U_SUN_VALID] = sun_B, bool(sun_valid)
        u[U_R_BN:U_R_BN + 3], u[U_R_SN:U_R_SN + 3] = r_BN_N, r_SN_N
        u[U_RATE:U_RATE + 3], u[U_TORQUE:U_TORQUE + 3] = omega_meas, torque
        if coarse_sun is None:
            u[U_COARSE:U_COARSE + 3], u[U_COARSE_VALID] = 0.0, False
        else:
            u[U_COARSE:U_COARSE + 3], u[U_COARSE_VALID] = coarse_sun[0], bool(coarse_sun[1])
        u[U_Q_TRUE:U_Q_TRUE + 4], u[U_RATE_TRUE:U_RATE_TRUE + 3] = (0.0, 0.0, 0.0, 1.0), 0.0
        self.step_packed(u, h)

    def step_packed(self, u, h, check=False, y=None):
        """step() with its inputs packed in one array u (U_* positions; the valid flags 1.0 or
        0.0), then with `check` check() against u's true attitude, and the wrapper's outputs in
        y (Y_* positions). Returns 0 when y holds the outputs and the NEES was recorded, else
        (before the first fix, or a NEES the compiled code leaves to check()) neither.
        Between two vector updates the step is two compiled calls (_step_head, _step_tail)."""
        h = float(h)
        k = self._constants(h)
        f = self.filter
        due = _step_head(self.x, _NO_COVARIANCE if f.P is None else f.P, u, k)
        if due < 0:
            self._head_failed(due, u, h)
        if due == NOT_STARTED:
            measurements, coarse = self._unpacked(u)
            self._initialize(measurements, coarse)
            if not f.initialized and self.history is not None:
                self._from_history(measurements, coarse, u[U_RATE:U_RATE + 3].tolist(), h)
        elif due:
            self._update(due, u)
        return _step_tail(self.x, _NO_COVARIANCE if f.P is None else f.P, u, k, self._y if y is None else y,
                          bool(check))

    def _constants(self, h):
        """The constants of a step of h seconds (K_* positions), kept while h stays."""
        k = self._k
        if h != self._k_h:
            self.rates.step_constants(k, h)
            k[K_QV], k[K_QU] = self.filter.sigma_v ** 2, self.filter.sigma_u ** 2
            k[K_INTERVAL], k[K_COARSE], k[K_TWO] = self.update_interval, self.coarse_triad is not None, 2.0
            k[K_J:K_J + 9], k[K_J_INV:K_J_INV + 9] = self.rates._k[K_J:K_J + 9], self.rates._k[K_J_INV:K_J_INV + 9]
            self._k_h = h
        return k

    def _unpacked(self, u):
        """(measurements, coarse) of step() from the packed inputs."""
        v = u.tolist()
        measurements = (v[U_NADIR:U_NADIR + 3], v[U_NADIR_VALID] != 0.0, v[U_SUN:U_SUN + 3], v[U_SUN_VALID] != 0.0,
                        v[U_R_BN:U_R_BN + 3], v[U_R_SN:U_R_SN + 3])
        coarse = (v[U_COARSE:U_COARSE + 3], True) \
            if self.coarse_triad is not None and v[U_COARSE_VALID] != 0.0 else None
        return measurements, coarse

    def _head_failed(self, code, u, h):
        """Raise what the Python code raised where _step_head stopped."""
        mean = [0.5 * (a + b) for a, b in zip(self.held_rate, u[U_RATE:U_RATE + 3].tolist())]
        if code == RATE_NOT_FINITE:
            raise ValueError(f"omega_meas_B {mean} must be finite")
        triad.propagate(self.filter.q, self.filter.rate(mean), h)  # raises: no rotation axis
        raise AssertionError(f"the compiled attitude propagation stopped ({code}) where the Python code did not")

    def _update(self, due, u):
        """The vector updates of the sensors `due` (1 nadir, 2 Sun, 4 coarse Sun), the covariance
        propagated before them (_step_head)."""
        f, v = self.filter, u.tolist()
        r_BN_N, r_SN_N = v[U_R_BN:U_R_BN + 3], v[U_R_SN:U_R_SN + 3]
        sun_N = [s - r for s, r in zip(r_SN_N, r_BN_N)]
        updates = []  # (sensor, measured vector, reference direction, sigma) of the new samples
        if due & 1:
            updates.append(("nadir", v[U_NADIR:U_NADIR + 3], [-x for x in r_BN_N], self.nadir_sigma))
        if due & 2:
            updates.append(("sun", v[U_SUN:U_SUN + 3], sun_N, self.sun_sigma))
        if due & 4:
            updates.append(("coarse", v[U_COARSE:U_COARSE + 3], sun_N, self.coarse_sigma))
        # watched once the bias is learned (while it is being learned the filter adapts anyway)
        armed = bool(self.innovations.window) and max(f.bias_sigma()) < BIAS_LEARNED * self.sigma_bias0
        if due & 6:
            self.without_sun = self.bias_held = False  # a Sun vector: the bias observable again
        for name, b, r, sigma in updates:
            self._mark(name, b)
            if self.innovations.add(*f.update(b, r, sigma, update_bias=not self.bias_held), armed):
                f.reopen_bias(self.sigma_bias0, self.innovations.error_variance())
                self.innovations.restart()
                self.bias_held = False  # a bias changed by a fault is learned again from what observes it

    def _initialize(self, measurements, coarse):
        """Start the filter from a TRIAD fix (the fine Sun vector, else the coarse one), if possible."""
        nadir_B, nadir_valid, sun_B, sun_valid, r_BN_N, r_SN_N = measurements
        q, sun_sigma, sun_used = self.triad.fix(*measurements), self.sun_sigma, ("sun", sun_B)
        if q is None and coarse is not None:
            q = self.coarse_triad.fix(nadir_B, nadir_valid, coarse[0], True, r_BN_N, r_SN_N)
            sun_sigma, sun_used = self.coarse_sigma, ("coarse", coarse[0])
        if q is None:
            return
        nadir_N = [-x for x in r_BN_N]
        sun_N = [s - r for s, r in zip(r_SN_N, r_BN_N)]
        angle = math.acos(max(-1.0, min(1.0, rotations.dot(triad._unit(nadir_N, "nadir"), triad._unit(sun_N, "Sun")))))
        first, second = sorted((self.nadir_sigma, sun_sigma))
        sigma = triad.triad_error_rms(first * math.sqrt(2.0), second * math.sqrt(2.0), angle) / math.sqrt(3.0)
        self.filter.initialize(q, max(sigma, 1e-6), sigma_bias=self.sigma_bias0)
        self._mark("nadir", nadir_B)
        self._mark(*sun_used)

    def _from_history(self, measurements, coarse, omega_meas, h):
        """Before a TRIAD fix: keep the gyro and the horizon sensor's samples, and once the history
        spans nadir_history_time and the spacecraft has been sunlit (the conical shadow from the
        GPS position and the Sun's) for sun_missing_time with no Sun vector from any sensor (they
        have failed: the coarse sensors see the Sun whenever it shines), start the filter from the
        history's fix. Until then nothing here changes what the estimator does."""
        nadir_B, nadir_valid, _, sun_valid, r_BN_N, r_SN_N = measurements
        if self.history.elapsed > HISTORY_KEPT * self.nadir_history_time:
            self.history.clear()  # bounded: a Sun seen but no TRIAD possible for long would grow it
        new = nadir_valid and self._new("nadir", nadir_B)
        self.history.add(omega_meas, h if self.history.rates else None, nadir_B if new else None,
                         [-x for x in r_BN_N] if new else None)
        if new:
            self._mark("nadir", nadir_B)
        if not (sun_valid or coarse is not None) and _sunlit(r_BN_N, r_SN_N):
            self.sunlit_without_sun += h
        if not (new and self.history.span >= max(self.nadir_history_time, self.history.next_try) - 1e-9
                and self.sunlit_without_sun >= self.sun_missing_time - 1e-9):
            return
        if self.history.solve(self.filter, self.history_fix_sigma or math.inf) is None:
            return
        self.without_sun = self.bias_held = True
        self.history.clear()

    def check(self, q_true):
        """Record the attitude NEES against the true attitude (a simulation's diagnostic of the
        filter's consistency; nothing the filter uses). Returns it; 0 before the first fix."""
        if not self.filter.initialized:
            return 0.0
        nees = self.filter.attitude_nees(q_true)
        self.consistency.add(nees)
        return nees

    def get_state(self):
        return {"consistency": self.consistency.get_state(), "innovations": self.innovations.get_state(),
                "filter": self.filter.get_state(), "rates": self.rates.get_state(), "time": self.time,
                "cov_pending": self.cov_pending, "cov_rate": list(self.cov_rate),
                "held_rate": self.held_rate, "updated": {name: float(self._e[at]) for name, at in UPDATED.items()},
                "seen": {name: self._e[at:at + 3].tolist() for name, at in SEEN.items() if self._e[at + 3] != 0.0},
                "history": None if self.history is None else self.history.get_state(),
                "sunlit_without_sun": self.sunlit_without_sun, "without_sun": self.without_sun,
                "bias_held": self.bias_held}

    def set_state(self, state):
        self.consistency.set_state(state["consistency"])
        self.innovations.set_state(state["innovations"])
        self.filter.set_state(state["filter"])
        self.rates.set_state(state["rates"])
        e = self._e
        e[TIME], e[COV_PENDING], e[COV_RATE:COV_RATE + 3] = state["time"], state["cov_pending"], state["cov_rate"]
        e[HAS_HELD] = state["held_rate"] is not None
        if state["held_rate"] is not None:
            e[HELD:HELD + 3] = state["held_rate"]
        for name, at in UPDATED.items():
            e[at] = state["updated"][name]
        for name, at in SEEN.items():
            sample = state["seen"].get(name)
            e[at + 3] = sample is not None
            if sample is not None:
                e[at:at + 3] = sample
        if self.history is not None:
            self.history.set_state(state["history"])
        self.sunlit_without_sun, self.without_sun = float(state["sunlit_without_sun"]), bool(state["without_sun"])
        self.bias_held = bool(state["bias_held"])


_NO_COVARIANCE = np.zeros((6, 6))  # what the compiled step is given for P before the first fix (unread)


def _sunlit(r_BN_N, r_SN_N):
    """Some of the Sun's disk seen past the Earth (the conical shadow of
    components.environment.eclipse). Positions not set yet (zero: no shadow to compute) are not."""
    try:
        return sunlit_fraction(r_BN_N, r_SN_N) > 0.0
    except ValueError:
        return False
