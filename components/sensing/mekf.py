"""Multiplicative extended Kalman filter for attitude and gyro bias (thesis section 3.3.1).

The thesis determines the attitude with TRIAD (horizon and Sun sensors) and then propagates
it with a 3-axis gyro through an extended Kalman filter [44]. This is the standard MEKF of
Markley and Crassidis (2014, section 6.2; Lefferts, Markley and Shuster 1982):

state       q_BN (scalar last, kept unit) and the gyro bias b (rad/s)
error state dx = [dtheta, db]: q_true = dq(dtheta) (x) q, b_true = b + db       (6 x 1, cov. P)
propagate   omega = omega_meas - b;  q <- exp(omega h) (x) q   (triad.propagate, exact for a held rate)
            Phi = I + F h,  F = [[-[omega x], -I], [0, 0]]
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
import math

import numpy as np

from ..core import rotations
from . import triad


def _skew(v):
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


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

    @property
    def initialized(self):
        return self.q is not None

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
        return tuple(float(w) - float(b) for w, b in zip(omega_meas, self.bias))

    def propagate(self, omega_meas, h):
        self._need()
        w = self.rate(omega_meas)
        if not all(math.isfinite(x) for x in w):
            raise ValueError(f"omega_meas_B {list(omega_meas)} must be finite")
        self.q = triad.propagate(self.q, w, h)
        F = np.zeros((6, 6))
        F[:3, :3] = -_skew(w)
        F[:3, 3:] = -np.eye(3)
        phi = np.eye(6) + F * h
        Qd = np.diag([self.sigma_v ** 2] * 3 + [self.sigma_u ** 2] * 3) * h  # G = diag(-I, I): G Q G^T = Q
        self.P = phi @ self.P @ phi.T + Qd

    def update(self, b_meas, r_ref, sigma):
        """Fuse one measured unit vector b_meas (B) of the reference direction r_ref (N)."""
        self._need()
        b = np.array(triad._unit(b_meas, "measured vector"))
        r = triad._unit(r_ref, "reference vector")
        s = _sigma("measurement sigma", sigma, "rad", positive=True)
        b_hat = np.array(rotations.attitude_matrix(self.q)) @ np.array(r)
        H = np.zeros((3, 6))
        H[:, :3] = _skew(b_hat)
        R = np.eye(3) * s * s
        S = H @ self.P @ H.T + R
        K = self.P @ H.T @ np.linalg.inv(S)
        dx = K @ (b - b_hat)
        dq = rotations.quaternion_rate(self.q, dx[:3])  # 1/2 Xi(q) dtheta
        self.q = rotations.normalized(tuple(qi + di for qi, di in zip(self.q, dq)), "q")
        self.bias = self.bias + dx[3:]
        IKH = np.eye(6) - K @ H
        self.P = IKH @ self.P @ IKH.T + K @ R @ K.T

    def attitude_sigma(self):
        """1-sigma attitude errors (rad) about the body axes: sqrt of the diagonal of P."""
        self._need()
        return tuple(float(math.sqrt(max(0.0, self.P[i, i]))) for i in range(3))

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


class AttitudeEstimator:
    """TRIAD to start, then the MEKF (thesis section 3.3.1): the estimator the controllers fly on.

    step(measurements, omega_meas, h) at each communication point: before the first TRIAD fix
    (both vectors valid and apart, triad.AttitudeDetermination.fix) it only waits; the fix
    initializes the filter with the first-order TRIAD error; afterwards every valid vector
    updates it (none in eclipse: no Sun vector) and the gyro propagates it over the step."""

    def __init__(self, nadir_sigma=math.radians(0.25), sun_sigma=math.radians(0.5) / 3.0,
                 sigma_v=5.5e-4 * math.sqrt(0.1), sigma_u=1e-6, sigma_bias0=1e-3, min_separation=math.radians(5.0)):
        self.triad = triad.AttitudeDetermination(nadir_sigma, sun_sigma, min_separation=min_separation)
        self.filter = AttitudeMEKF(sigma_v, sigma_u)
        self.sigma_bias0 = _sigma("sigma_bias0", sigma_bias0, "rad/s", positive=True)
        # per-axis sigmas of the vector measurements (the sensors' error angle RMS over two axes)
        self.nadir_sigma = max(self.triad.nadir_sigma, 1e-6) / math.sqrt(2.0)
        self.sun_sigma = max(self.triad.sun_sigma, 1e-6) / math.sqrt(2.0)

    def step(self, measurements, omega_meas, h):
        nadir_B, nadir_valid, sun_B, sun_valid, r_BN_N, r_SN_N = measurements
        f = self.filter
        if not f.initialized:
            q = self.triad.fix(*measurements)
            if q is None:
                return
            nadir_N = [-x for x in r_BN_N]
            sun_N = [s - r for s, r in zip(r_SN_N, r_BN_N)]
            angle = math.acos(max(-1.0, min(1.0, rotations.dot(triad._unit(nadir_N, "nadir"),
                                                                triad._unit(sun_N, "Sun")))))
            first, second = sorted((self.nadir_sigma, self.sun_sigma))
            sigma = triad.triad_error_rms(first * math.sqrt(2.0), second * math.sqrt(2.0), angle) / math.sqrt(3.0)
            f.initialize(q, max(sigma, 1e-6), sigma_bias=self.sigma_bias0)
        else:
            if nadir_valid:
                f.update(nadir_B, [-x for x in r_BN_N], self.nadir_sigma)
            if sun_valid:
                f.update(sun_B, [s - r for s, r in zip(r_SN_N, r_BN_N)], self.sun_sigma)
        f.propagate(omega_meas, h)

    def get_state(self):
        return {"filter": self.filter.get_state()}

    def set_state(self, state):
        self.filter.set_state(state["filter"])
