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


def _sigma(name, value, unit, positive=False):
    value = float(value)
    if not (math.isfinite(value) and (value > 0.0 if positive else value >= 0.0)):
        raise ValueError(f"{name} = {value!r} must be a finite number {'>' if positive else '>='} 0 ({unit})")
    return value


class AttitudeMEKF:
    """sigma_v (rad/s^0.5), sigma_u (rad/s^1.5); initialize() before the first propagate/update."""

    def __init__(self, sigma_v=5.5e-4 * math.sqrt(0.1), sigma_u=1e-6):
        self.sigma_v = _sigma("sigma_v", sigma_v, "rad/s^0.5")
        self.sigma_u = _sigma("sigma_u", sigma_u, "rad/s^1.5")
        self.q = None
        self.bias = np.zeros(3)
        self.P = None
        self._block, self._block_of = None, None  # P's attitude block as lists, and the P it is of

    @property
    def initialized(self):
        return self.q is not None

    @property
    def bias(self):
        """The gyro bias estimate (rad/s), an array."""
        return self._bias

    @bias.setter
    def bias(self, value):
        self._bias = value
        self._bias_floats = (float(value[0]), float(value[1]), float(value[2])) if len(value) == 3 else None

    def _attitude_block(self):
        """P's attitude block as nested lists, kept while P is the same array (the NEES and the
        sigmas read it at every step; P changes at covariance propagations and updates)."""
        P = self.P
        if self._block_of is not P:
            self._block, self._block_of = P[:3, :3].tolist(), P
        return self._block

    def initialize(self, q, sigma_attitude, bias=(0.0, 0.0, 0.0), sigma_bias=1e-3):
        """Start from q (e.g. a TRIAD fix) with 1-sigma errors sigma_attitude (rad) per axis and
        sigma_bias (rad/s) on the bias."""
        self.q = rotations.normalized(tuple(float(x) for x in q), "q")
        self.bias = np.array([float(x) for x in bias])
        if self.bias.shape != (3,) or not np.all(np.isfinite(self.bias)):
            raise ValueError(f"bias {list(bias)} must be three finite numbers (rad/s)")
        sa = _sigma("sigma_attitude", sigma_attitude, "rad", positive=True)
        sb = _sigma("sigma_bias", sigma_bias, "rad/s", positive=True)
        self.P = np.diag([sa * sa] * 3 + [sb * sb] * 3)

    def _need(self):
        if not self.initialized:
            raise ValueError("the filter is not initialized (no attitude fix yet)")

    def rate(self, omega_meas):
        """The rate estimate omega_meas - b (rad/s)."""
        b = self._bias_floats
        return (float(omega_meas[0]) - b[0], float(omega_meas[1]) - b[1], float(omega_meas[2]) - b[2])

    def propagate(self, omega_meas, h, covariance=True):
        """Attitude over h with the bias-corrected rate held; the covariance too unless the
        caller gathers several steps into one propagate_covariance (first order up to EXACT_ANGLE)."""
        self._need()
        w = self.rate(omega_meas)
        if not (math.isfinite(w[0]) and math.isfinite(w[1]) and math.isfinite(w[2])):
            raise ValueError(f"omega_meas_B {list(omega_meas)} must be finite")
        self.q = triad.propagate(self.q, w, h)
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
        b = np.array(triad._unit(b_meas, "measured vector"))
        r = triad._unit(r_ref, "reference vector")
        s = _sigma("measurement sigma", sigma, "rad", positive=True)
        A = rotations.attitude_matrix(self.q)
        b_hat = np.array([A[i][0] * r[0] + A[i][1] * r[1] + A[i][2] * r[2] for i in range(3)])
        y = b - b_hat
        self.P, dx, nis = _vector_update(self.P, b_hat, y, s * s, bool(update_bias))
        dq = rotations.quaternion_rate(self.q, dx[:3])  # 1/2 Xi(q) dtheta
        self.q = rotations.normalized(tuple(qi + di for qi, di in zip(self.q, dq)), "q")
        self.bias = self.bias + dx[3:]
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
        self._block_of = None  # changed in place

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
    factor L (A = L L^T: the value is |L^-1 d|^2), in plain floats: at every step of the mission
    numpy's solve costs ten times more in its call overhead than in the arithmetic. None when A
    is not positive definite."""
    a00, a10, a11, a20, a21, a22 = A[0][0], A[1][0], A[1][1], A[2][0], A[2][1], A[2][2]
    if not a00 > 0.0:
        return None
    l00 = math.sqrt(a00)
    l10, l20 = a10 / l00, a20 / l00
    p11 = a11 - l10 * l10
    if not p11 > 0.0:
        return None
    l11 = math.sqrt(p11)
    l21 = (a21 - l20 * l10) / l11
    p22 = a22 - l20 * l20 - l21 * l21
    if not p22 > 0.0:
        return None
    l22 = math.sqrt(p22)
    y0 = d[0] / l00
    y1 = (d[1] - l10 * y0) / l11
    y2 = (d[2] - l20 * y0 - l21 * y1) / l22
    return y0 * y0 + y1 * y1 + y2 * y2


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _times(M, v):
    m0, m1, m2 = M
    return (m0[0] * v[0] + m0[1] * v[1] + m0[2] * v[2], m1[0] * v[0] + m1[1] * v[1] + m1[2] * v[2],
            m2[0] * v[0] + m2[1] * v[1] + m2[2] * v[2])


class RateFilter:
    """Body-rate estimate for the controllers: per axis a Kalman filter whose prediction is Euler's
    equation with the commanded torque, J omega_dot = L - omega x J omega, and whose measurement
    is the bias-corrected gyro rate (variance sigma_v^2 / h per sample at step h). The torque
    model carries the estimate through a firing without the lag of a plain low-pass filter;
    `accel_sigma` (rad/s^2, the 1-sigma unmodelled angular acceleration: thruster force and
    direction errors, disturbances) sets how much the gyro is trusted over the model.
    Plain floats: it runs at every 15 ms step of the mission."""

    def __init__(self, inertia, sigma_v, accel_sigma):
        J = np.array(inertia, dtype=float).reshape(3, 3)
        if not np.all(np.isfinite(J)) or np.any(np.linalg.eigvalsh(0.5 * (J + J.T)) <= 0.0):
            raise ValueError(f"inertia {J.tolist()} must be finite and positive definite (kg.m2)")
        self.J, self.J_inv = J.tolist(), np.linalg.inv(J).tolist()
        self.sigma_v = _sigma("sigma_v", sigma_v, "rad/s^0.5")
        self.accel_sigma = _sigma("rate accel_sigma", accel_sigma, "rad/s^2")
        self.omega = None  # no estimate before the first sample
        self.P = [0.0, 0.0, 0.0]
        self.omega_dot = (0.0, 0.0, 0.0)

    def acceleration(self, torque):
        w = self.omega
        gyroscopic = _cross(w, _times(self.J, w))
        return _times(self.J_inv, [float(torque[i]) - gyroscopic[i] for i in range(3)])

    def predict(self, torque, h):
        """Carry the estimate over a step of h seconds with the torque commanded over it."""
        if self.omega is None:
            return
        a = self.omega_dot = self.acceleration(torque)
        self.omega = [self.omega[i] + a[i] * h for i in range(3)]
        q = (self.accel_sigma * h) ** 2
        self.P = [p + q for p in self.P]

    def update(self, omega_corrected, h):
        """Fuse one bias-corrected gyro sample taken at the end of a step of h seconds."""
        z = [float(x) for x in omega_corrected]
        R = self.sigma_v ** 2 / max(h, 1e-9)
        if self.omega is None:
            self.omega, self.P = z, [R, R, R]
            return
        for i in range(3):
            k = self.P[i] / (self.P[i] + R)
            self.omega[i] += k * (z[i] - self.omega[i])
            self.P[i] *= 1.0 - k

    def get_state(self):
        return {"omega": None if self.omega is None else list(self.omega), "P": list(self.P),
                "omega_dot": list(self.omega_dot)}

    def set_state(self, state):
        self.omega = None if state["omega"] is None else [float(x) for x in state["omega"]]
        self.P = [float(x) for x in state["P"]]
        self.omega_dot = tuple(float(x) for x in state["omega_dot"])


# 95 % quantile of the chi-square distribution with 3 degrees of freedom (scipy.stats.chi2.ppf(0.95, 3))
NEES_BOUND_95 = 7.814727903251178


class NeesMonitor:
    """The attitude NEES over the steps it is given: its mean (3 when the covariance is
    consistent) and the share of steps above NEES_BOUND_95 (0.05 when consistent)."""

    def __init__(self):
        self.count, self.total, self.over, self.last = 0, 0.0, 0, 0.0

    def add(self, nees):
        self.count += 1
        self.total += nees
        self.over += nees > NEES_BOUND_95
        self.last = nees

    @property
    def mean(self):
        return self.total / self.count if self.count else 0.0

    @property
    def over_fraction(self):
        return self.over / self.count if self.count else 0.0

    def get_state(self):
        return {"count": self.count, "total": self.total, "over": self.over, "last": self.last}

    def set_state(self, state):
        self.count, self.total = int(state["count"]), float(state["total"])
        self.over, self.last = int(state["over"]), float(state["last"])


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
        self.filter = AttitudeMEKF(sigma_v, sigma_u)
        self.rates = RateFilter(np.diag([0.05, 0.1, 0.1]) if inertia is None else inertia, sigma_v, accel_sigma)
        self.sigma_bias0 = _sigma("sigma_bias0", sigma_bias0, "rad/s", positive=True)
        self.update_interval = _sigma("update_interval", update_interval, "s")
        # per-axis sigmas of the vector measurements (the sensors' error angle RMS over two axes)
        self.nadir_sigma = max(self.triad.nadir_sigma, 1e-6) / math.sqrt(2.0)
        self.sun_sigma = max(self.triad.sun_sigma, 1e-6) / math.sqrt(2.0)
        self.coarse_sigma = None if coarse_sun_sigma is None else \
            max(self.coarse_triad.sun_sigma, 1e-6) / math.sqrt(2.0)
        self.time = 0.0
        self.cov_pending, self.cov_rate = 0.0, (0.0, 0.0, 0.0)  # covariance propagation gathered
        self.held_rate = None  # the gyro sample of the step's start
        self.consistency = NeesMonitor()  # against the truth, where a simulation gives it (check)
        self.innovations = InnovationMonitor(fault_window, fault_limit)
        self.updated = {"nadir": -math.inf, "sun": -math.inf, "coarse": -math.inf}  # sensor -> time of its last update
        self.seen = {}  # sensor -> the sample it gave at the last step
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

    def _new(self, name, vector):
        """A sample to use now: it has just arrived (it differs from the one this sensor gave at
        the last step) and update_interval has passed since the last update from this sensor. A
        sample that arrives sooner is dropped, not kept for later: used later it would be older
        than the estimate it corrects (a held sample 6 steps late is 1.5 deg off at 17 deg/s)."""
        vector = tuple(vector)
        arrived = vector != self.seen.get(name)
        self.seen[name] = vector
        return arrived and self.time - self.updated[name] >= self.update_interval - 1e-9

    def _mark(self, name, vector):
        self.updated[name] = self.time
        self.seen[name] = tuple(vector)

    def step(self, measurements, omega_meas, h, torque=(0.0, 0.0, 0.0), coarse_sun=None):
        """measurements = (nadir_B, nadir_valid, sun_B, sun_valid, r_BN_N, r_SN_N);
        coarse_sun = (sun_B, valid) of the coarse sensors, used only with coarse_sun_sigma."""
        nadir_B, nadir_valid, sun_B, sun_valid, r_BN_N, r_SN_N = measurements
        coarse = coarse_sun if self.coarse_triad is not None and coarse_sun is not None and coarse_sun[1] else None
        f = self.filter
        self.time += h
        if f.initialized and self.held_rate is not None:
            mean = [0.5 * (a + float(b)) for a, b in zip(self.held_rate, omega_meas)]
            f.propagate(mean, h, covariance=False)
            self.cov_pending += h
            self.cov_rate = f.rate(mean)
        self.rates.predict(torque, h)
        if not f.initialized:
            self._initialize(measurements, coarse)
            if not f.initialized and self.history is not None:
                self._from_history(measurements, coarse, omega_meas, h)
        else:
            sun_N = [s - r for s, r in zip(r_SN_N, r_BN_N)]
            updates = []  # (sensor, measured vector, reference direction, sigma) of the new samples
            if nadir_valid and self._new("nadir", nadir_B):
                updates.append(("nadir", nadir_B, [-x for x in r_BN_N], self.nadir_sigma))
            if sun_valid:
                if self._new("sun", sun_B):
                    updates.append(("sun", sun_B, sun_N, self.sun_sigma))
            elif coarse is not None and self._new("coarse", coarse[0]):
                updates.append(("coarse", coarse[0], sun_N, self.coarse_sigma))
            if updates or self.cov_pending >= COVARIANCE_STEP - 1e-9:
                self._propagate_covariance()  # the covariance must be current before an update
            # watched once the bias is learned (while it is being learned the filter adapts anyway)
            armed = bool(updates and self.innovations.window) and max(f.bias_sigma()) < BIAS_LEARNED * self.sigma_bias0
            if any(name != "nadir" for name, _, _, _ in updates):
                self.without_sun = self.bias_held = False  # a Sun vector: the bias observable again
            for name, b, r, sigma in updates:
                self._mark(name, b)
                if self.innovations.add(*f.update(b, r, sigma, update_bias=not self.bias_held), armed):
                    f.reopen_bias(self.sigma_bias0, self.innovations.error_variance())
                    self.innovations.restart()
                    self.bias_held = False  # a bias changed by a fault is learned again from what observes it
        self.held_rate = (float(omega_meas[0]), float(omega_meas[1]), float(omega_meas[2]))
        self.rates.update(f.rate(self.held_rate), h)

    def _propagate_covariance(self):
        if self.cov_pending > 0.0:
            self.filter.propagate_covariance(self.cov_rate, self.cov_pending)
            self.cov_pending = 0.0

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
                "held_rate": self.held_rate, "updated": dict(self.updated),
                "seen": {k: list(v) for k, v in self.seen.items()},
                "history": None if self.history is None else self.history.get_state(),
                "sunlit_without_sun": self.sunlit_without_sun, "without_sun": self.without_sun,
                "bias_held": self.bias_held}

    def set_state(self, state):
        self.consistency.set_state(state["consistency"])
        self.innovations.set_state(state["innovations"])
        self.filter.set_state(state["filter"])
        self.rates.set_state(state["rates"])
        self.time = float(state["time"])
        self.cov_pending, self.cov_rate = float(state["cov_pending"]), tuple(state["cov_rate"])
        self.held_rate = None if state["held_rate"] is None else tuple(state["held_rate"])
        self.updated = {k: float(t) for k, t in state["updated"].items()}
        self.seen = {k: tuple(v) for k, v in state["seen"].items()}
        if self.history is not None:
            self.history.set_state(state["history"])
        self.sunlit_without_sun, self.without_sun = float(state["sunlit_without_sun"]), bool(state["without_sun"])
        self.bias_held = bool(state["bias_held"])


def _sunlit(r_BN_N, r_SN_N):
    """Some of the Sun's disk seen past the Earth (the conical shadow of
    components.environment.eclipse). Positions not set yet (zero: no shadow to compute) are not."""
    try:
        return sunlit_fraction(r_BN_N, r_SN_N) > 0.0
    except ValueError:
        return False
