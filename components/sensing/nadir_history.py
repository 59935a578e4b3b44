"""Attitude without the Sun: a history of horizon-sensor nadir vectors, the gyro and the GPS.

One nadir vector fixes two of the attitude's three angles; the rotation about the nadir is what
the Sun vector gives TRIAD. Over time the nadir turns in inertial space (at the orbital rate,
about the orbit normal) and the body turns under the gyro: with the gyro carrying the body from
one sample to the next, nadir vectors taken at different times are different directions in one
frame, and together they fix the whole attitude and the gyro's bias. This is the single-vector
attitude problem with a gyro, observable when the reference direction moves, solved here in two
passes over the stored samples:

1. Batch least squares (Gauss-Newton) for the attitude A0 at the history's start and the gyro
   bias b: the body's rotation from the start to sample k, D_k, is integrated from the gyro less
   b (the mean of consecutive samples held over each step, as the estimator propagates); the
   model of sample k is D_k A0 r_k with r_k the nadir from the GPS position. Linearized about
   (A0, b): y_k = [n_k x](D_k dtheta0 - G_k db), G_{k+1} = M_k G_k + h I (M_k the step's
   rotation), the MEKF's error dynamics. The rotation about the first nadir is unknown, so the
   iterations start from 12 guesses 30 deg apart about it (bias 0) and the best fit is kept.
2. The MEKF (components.sensing.mekf.AttitudeMEKF) from that start, with a covariance wide
   enough for the batch's error, forward over the same samples: its end state is the estimate at
   the last sample, with the covariance of a filter that models the gyro's noise (the batch's
   own covariance would not: it treats the integrated gyro as exact).

Measured (tests/components/sensing/test_nadir_history.py; 420 km, BMG160 gyro, 0.25 deg horizon
sensor, a bias of 1 mrad/s per axis, 1200 s): a body tumbling at 10-15 deg/s or turning at the
bias rate alone ends within 0.1-0.6 deg, consistent with the filter's covariance. In the 475 km
dispersed missions the fixes were less accurate (one 4.4 deg off with a 0.6 deg sigma; docs/models/mission.md).
"""
import math

import numpy as np

from ..core import jit, rotations
from ..core.jit import njit

YAW_GUESSES = 12  # starts about the first nadir, 30 deg apart
SCREEN_ITERATIONS = 3  # Gauss-Newton iterations per start before the best is chosen
MAX_ITERATIONS = 15


def _skew(v):
    """[v x] for each row of v (n, 3)."""
    z = np.zeros(len(v))
    return np.stack([np.stack([z, -v[:, 2], v[:, 1]], 1), np.stack([v[:, 2], z, -v[:, 0]], 1),
                     np.stack([-v[:, 1], v[:, 0], z], 1)], 1)


def _integrate_numpy(rates, h, bias):
    """_integrate without numba: the steps' rotations built at once, the products in numpy (the
    element loops in plain Python would take a minute for 20 minutes of 0.1 s samples)."""
    w = 0.5 * (rates[:-1] + rates[1:]) - bias
    wn = np.linalg.norm(w, axis=1)
    angle = wn * h
    e = np.divide(w, wn[:, None], out=np.zeros_like(w), where=wn[:, None] > 0.0)
    c, s = np.cos(angle)[:, None, None], np.sin(angle)[:, None, None]
    M = c * np.eye(3) + (1.0 - c) * np.einsum("ki,kj->kij", e, e) - s * _skew(e)
    n = h.shape[0]
    D = np.empty((n + 1, 3, 3))
    G = np.empty((n + 1, 3, 3))
    D[0], G[0] = np.eye(3), np.zeros((3, 3))
    eye = np.eye(3)
    for k in range(n):
        D[k + 1] = M[k] @ D[k]
        G[k + 1] = M[k] @ G[k] + h[k] * eye
    return D, G


@njit(cache=True)
def _looped_integrate(rates, h, bias):
    """D_k (the body's rotation, frame at sample 0 to frame at sample k) and G_k (d attitude error /
    d bias, body frame at k) for k = 0..n, from the gyro samples `rates` (n+1, 3) less `bias`, the
    mean of consecutive samples held over each step h[k]."""
    n = h.shape[0]
    D = np.empty((n + 1, 3, 3))
    G = np.empty((n + 1, 3, 3))
    D[0] = np.eye(3)
    G[0] = np.zeros((3, 3))
    for k in range(n):
        w0 = 0.5 * (rates[k, 0] + rates[k + 1, 0]) - bias[0]
        w1 = 0.5 * (rates[k, 1] + rates[k + 1, 1]) - bias[1]
        w2 = 0.5 * (rates[k, 2] + rates[k + 1, 2]) - bias[2]
        wn = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
        angle = wn * h[k]
        M = np.eye(3)
        if angle > 0.0:
            e0, e1, e2 = w0 / wn, w1 / wn, w2 / wn
            c, s = math.cos(angle), math.sin(angle)
            t = 1.0 - c
            # A = cos I + (1 - cos) e e^T - sin [e x]: body coordinates after turning by angle about e
            M[0, 0], M[0, 1], M[0, 2] = c + t * e0 * e0, t * e0 * e1 + s * e2, t * e0 * e2 - s * e1
            M[1, 0], M[1, 1], M[1, 2] = t * e1 * e0 - s * e2, c + t * e1 * e1, t * e1 * e2 + s * e0
            M[2, 0], M[2, 1], M[2, 2] = t * e2 * e0 + s * e1, t * e2 * e1 - s * e0, c + t * e2 * e2
        for i in range(3):
            for j in range(3):
                d = 0.0
                g = 0.0
                for m in range(3):
                    d += M[i, m] * D[k, m, j]
                    g += M[i, m] * G[k, m, j]
                D[k + 1, i, j] = d
                G[k + 1, i, j] = g + (h[k] if i == j else 0.0)
    return D, G


_integrate = _looped_integrate if jit.ENABLED else _integrate_numpy


def _rotation(axis_angle):
    """Attitude matrix of the small-or-not rotation vector (rad): body coordinates after turning."""
    angle = float(np.linalg.norm(axis_angle))
    if angle == 0.0:
        return np.eye(3)
    return np.array(rotations.attitude_matrix(rotations.from_axis_angle(axis_angle, angle)))


def _turning(a, b):
    """A rotation matrix M with M a = b (unit vectors), as an attitude matrix of a body whose
    coordinates of the fixed vector a become b."""
    axis = np.cross(b, a)  # attitude_matrix turns coordinates the other way from the active rotation
    s, c = float(np.linalg.norm(axis)), float(a @ b)
    if s < 1e-12:
        if c > 0.0:
            return np.eye(3)
        p = np.eye(3)[int(np.argmin(np.abs(a)))]
        axis = np.cross(a, p)
        return _rotation(axis / np.linalg.norm(axis) * math.pi)
    return _rotation(axis / s * math.atan2(s, c))


class NadirHistory:
    """Samples for an attitude fix without the Sun; add() at every step of the estimator, solve()
    once `span` is long enough.

    nadir_sigma: the horizon sensor's error angle RMS (rad, over two axes, as the estimator's
    nadir_sigma); sigma_bias0 (rad/s): the bias' prior; start_sigma (rad): the attitude sigma the
    filter pass starts from (wider than the batch's error)."""

    def __init__(self, nadir_sigma, sigma_bias0, start_sigma=math.radians(5.0)):
        self.nadir_sigma = float(nadir_sigma)
        self.sigma_bias0 = float(sigma_bias0)
        self.start_sigma = float(start_sigma)
        self.clear()

    def clear(self):
        self.rates = []  # gyro samples; rates[k] at the end of step k - 1 (rates[0]: the first held)
        self.steps = []  # step lengths (s), len(rates) - 1 of them
        self.nadir = []  # (sample index, nadir_B, nadir_N unit)
        self.elapsed = 0.0  # s from the first gyro sample to the last
        self.span = 0.0  # s from the first gyro sample to the last nadir sample

    def get_state(self):
        return {"rates": [list(r) for r in self.rates], "steps": list(self.steps),
                "nadir": [[k, b.tolist(), r.tolist()] for k, b, r in self.nadir], "elapsed": self.elapsed,
                "span": self.span}

    def set_state(self, state):
        self.rates = [tuple(float(x) for x in r) for r in state["rates"]]
        self.steps = [float(h) for h in state["steps"]]
        self.nadir = [(int(k), np.array(b, dtype=float), np.array(r, dtype=float)) for k, b, r in state["nadir"]]
        self.elapsed, self.span = float(state["elapsed"]), float(state["span"])

    def add(self, omega_meas, h=None, nadir_B=None, nadir_N=None):
        """A gyro sample at the end of a step of h seconds (None: the first sample), and the nadir
        measured now (B) with its direction from the GPS position (N), if a new one arrived."""
        if h is None:
            if self.rates:
                raise ValueError("only the first sample comes without a step length")
        else:
            if not self.rates:
                raise ValueError("the first sample comes without a step length")
            self.steps.append(float(h))
            self.elapsed += float(h)
        self.rates.append(tuple(float(x) for x in omega_meas))
        if nadir_B is not None:
            b = np.array(nadir_B, dtype=float)
            r = np.array(nadir_N, dtype=float)
            self.nadir.append((len(self.rates) - 1, b / np.linalg.norm(b), r / np.linalg.norm(r)))
            self.span = self.elapsed

    def _fit(self, A0, bias, rates, h, index, n_B, n_N, iterations, integrated=None):
        """Gauss-Newton from (A0, bias); returns (A0, bias, the fit's sum of squares).
        `integrated`: _integrate(rates, h, bias) when the caller has it already."""
        cost = math.inf
        for _ in range(iterations):
            D, G = _integrate(rates, h, bias) if integrated is None else integrated
            integrated = None
            Dk, Gk = D[index], G[index]
            pred = np.einsum("kij,jl,kl->ki", Dk, A0, n_N)
            y = n_B - pred
            cost = float(np.einsum("ki,ki->", y, y))
            S = _skew(pred)
            H = np.concatenate([S @ Dk, -(S @ Gk)], axis=2).reshape(-1, 6)
            dx = np.linalg.lstsq(H, y.reshape(-1), rcond=None)[0]
            A0 = _rotation(dx[:3]) @ A0
            bias = bias + dx[3:]
            if np.linalg.norm(dx[:3]) < 1e-7 and np.linalg.norm(dx[3:]) < 1e-9:
                break
        return A0, bias, cost

    def solve(self, f):
        """Start the filter `f` (a mekf.AttitudeMEKF, whose own gyro model it keeps) from the
        history and run it over the samples: its state is then the estimate at the last nadir
        sample. Returns f, or None (f untouched) with fewer than 10 nadir samples."""
        if len(self.nadir) < 10:
            return None
        last = self.nadir[-1][0]
        rates = np.array(self.rates[:last + 1])
        h = np.array(self.steps[:last])
        index = np.array([k for k, _, _ in self.nadir])
        n_B = np.array([b for _, b, _ in self.nadir])
        n_N = np.array([r for _, _, r in self.nadir])
        # the first nadir in the start's frame, with no bias: A0 n_N[0] = D_0^T n_B[0]
        unbiased = _integrate(rates, h, np.zeros(3))  # every start's first iteration
        u = unbiased[0][index[0]].T @ n_B[0]
        base = _turning(n_N[0], u)
        best = None
        for i in range(YAW_GUESSES):
            start = _rotation(u * (2.0 * math.pi * i / YAW_GUESSES)) @ base
            fit = self._fit(start, np.zeros(3), rates, h, index, n_B, n_N, SCREEN_ITERATIONS, unbiased)
            if best is None or fit[2] < best[2]:
                best = fit
        A0, bias, _ = self._fit(best[0], best[1], rates, h, index, n_B, n_N, MAX_ITERATIONS)
        return self._filter(f, A0, bias, rates, h)

    def _filter(self, f, A0, bias, rates, h):
        """The filter f from (A0, bias) over the samples, to the last one."""
        f.initialize(rotations.dcm_to_quaternion(A0.tolist()), self.start_sigma, bias, self.sigma_bias0)
        sigma = max(self.nadir_sigma, 1e-6) / math.sqrt(2.0)
        samples = iter(self.nadir)
        k_next, b, r = next(samples)
        if k_next == 0:
            f.update(b, r, sigma)
            k_next, b, r = next(samples, (None, None, None))
        for k in range(len(h)):
            mean = [0.5 * (rates[k, i] + rates[k + 1, i]) for i in range(3)]
            f.propagate(mean, float(h[k]))
            if k + 1 == k_next:
                f.update(b, r, sigma)
                k_next, b, r = next(samples, (None, None, None))
        return f
