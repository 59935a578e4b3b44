"""Attitude without the Sun: a history of horizon-sensor nadir vectors, the gyro and the GPS.

One nadir vector fixes two of the attitude's three angles; the rotation about the nadir is what
the Sun vector gives TRIAD. Over time the nadir turns in inertial space (at the orbital rate,
about the orbit normal) and the body turns under the gyro: with the gyro carrying the body from
one sample to the next, nadir vectors taken at different times are different directions in one
frame, and together they fix the whole attitude and the gyro's bias. This is the single-vector
attitude problem with a gyro, observable when the reference direction moves, solved here in two
passes over the stored samples:

1. Batch least squares (Gauss-Newton) for the attitude A0 at the history's start and the gyro
   bias b, the gyro taken as exact: the body's rotation from the start to sample k, D_k, is
   integrated from the gyro less b (the mean of consecutive samples held over each step, as the
   estimator propagates); the model of sample k is D_k A0 r_k with r_k the nadir from the GPS
   position. Linearized about (A0, b): y_k = [n_k x](D_k dtheta0 - G_k db), G_{k+1} = M_k G_k + h I
   (M_k the step's rotation), the MEKF's error dynamics. The rotation about the first nadir is
   unknown, so the iterations start from 12 guesses 30 deg apart about it (bias 0), each run to
   its minimum, and from the best one's mirror image (_mirrors); the distinct minima that fit
   nearly as well as the best go on to step 2. This pass finds the basin; its estimate is not
   the answer, since over 20 minutes the gyro's noise turns the integrated body by about half a
   degree (a random walk), which the exact-gyro fit absorbs into a wrong start and bias (2 deg
   and 3 deg in one 475 km mission).
2. Smoothing with the gyro's noise: the attitude at knots KNOT_SPACING apart and the bias, each
   nadir sample tied to its knot by the gyro as above, consecutive knots tied by the gyro with
   the noise the filter assumes (sigma_v^2 per second per axis), the bias by the filter's prior;
   Gauss-Newton from the first pass. The normal equations are block tridiagonal in the knots
   with the bias coupled to all (solved by block elimination and the bias' Schur complement), so
   the cost grows linearly with the history's length. The best smoothed fit wins unless another distinct
   one fits about as well (ambiguous: no fix yet). The last knot is the last sample: the filter
   starts there with the estimate and the joint covariance of its attitude and the bias.

An earlier version ran the MEKF over the samples from the first pass' start in place of step 2:
started several degrees off with a 5 deg sigma, its linearization settled on a wrong attitude
with a narrow covariance (the 475 km mission's run 7: 4.4 deg off claiming 0.4 deg per axis, NEES
52; from the same data the smoothing is 1.6 deg off with 0.55-0.69 deg per axis, NEES 3.0).

Measured (bench/bench_nadir_history.py on the flight of tests/components/sensing/
test_nadir_history.py: 420 km, BMG160 gyro, 0.25 deg horizon sensor, a bias of 1 mrad/s per axis,
1200 s): a body tumbling at 5-13.5 deg/s ends 0.03-0.55 deg off, turning at the bias rate alone
within 4 deg (2 of 12 without a fix), consistent with the covariance (mean NEES 2.4); the solve
takes 1-3 s.
"""
import math

import numpy as np

from ..core import jit, rotations
from ..core.jit import njit

YAW_GUESSES = 12  # starts about the first nadir, 30 deg apart
MAX_ITERATIONS = 15
# Minima of the first pass more than DISTINCT_ANGLE apart and within CANDIDATE_RATIO of the best
# one's sum of squares are smoothed each; two smoothed fits that differ by less than AMBIGUOUS_CHI2
# are no fix. A body at rest in inertial space fits its history as well turned half a turn about
# the mid-arc nadir with a bias error of twice the orbital rate (_mirrors): only the bias' prior
# tells them apart, by a few units of chi-square. In the tests' tumbles the second minimum was
# 5 times worse or more in the first pass.
DISTINCT_ANGLE = math.radians(10.0)
CANDIDATE_RATIO = 2.0
AMBIGUOUS_CHI2 = 100.0
RETRY_TIME = 120.0  # s of further history before an ambiguous one is tried again
KNOT_SPACING = 2.0  # s between the smoothing's attitude knots


def _skew(v):
    """[v x] for each row of v (n, 3)."""
    z = np.zeros(len(v))
    return np.stack([np.stack([z, -v[:, 2], v[:, 1]], 1), np.stack([v[:, 2], z, -v[:, 0]], 1),
                     np.stack([-v[:, 1], v[:, 0], z], 1)], 1)


def _integrate_numpy(rates, h, bias):
    """_integrate without numba: the steps' rotations built at once, the products in numpy (the
    element loops in plain Python would take a minute for 20 minutes of 0.1 s samples)."""
    M = _rotations((0.5 * (rates[:-1] + rates[1:]) - bias) * h[:, None])
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


def _angle(E):
    """The rotation angle (rad) of the attitude matrix E."""
    return math.acos(max(-1.0, min(1.0, (float(np.trace(E)) - 1.0) / 2.0)))


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
    nadir_sigma); sigma_bias0 (rad/s): the bias' prior (about zero, as the filter's)."""

    def __init__(self, nadir_sigma, sigma_bias0):
        self.nadir_sigma = float(nadir_sigma)
        self.sigma_bias0 = float(sigma_bias0)
        self.clear()

    def clear(self):
        self.rates = []  # gyro samples; rates[k] at the end of step k - 1 (rates[0]: the first held)
        self.steps = []  # step lengths (s), len(rates) - 1 of them
        self.nadir = []  # (sample index, nadir_B, nadir_N unit)
        self.elapsed = 0.0  # s from the first gyro sample to the last
        self.span = 0.0  # s from the first gyro sample to the last nadir sample
        self.next_try = 0.0  # the span before which solve() is not tried again

    def get_state(self):
        return {"rates": [list(r) for r in self.rates], "steps": list(self.steps),
                "nadir": [[k, b.tolist(), r.tolist()] for k, b, r in self.nadir], "elapsed": self.elapsed,
                "span": self.span, "next_try": self.next_try}

    def set_state(self, state):
        self.rates = [tuple(float(x) for x in r) for r in state["rates"]]
        self.steps = [float(h) for h in state["steps"]]
        self.nadir = [(int(k), np.array(b, dtype=float), np.array(r, dtype=float)) for k, b, r in state["nadir"]]
        self.elapsed, self.span = float(state["elapsed"]), float(state["span"])
        self.next_try = float(state["next_try"])

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

    def solve(self, f, max_sigma=math.inf):
        """Start the filter `f` (a mekf.AttitudeMEKF, whose gyro noise sigma_v the smoothing
        takes) at the last nadir sample with the history's estimate and covariance. Returns f, or
        None (f untouched) with fewer than 10 nadir samples, when two distinct attitudes fit the
        history alike, or when the estimate's largest 1-sigma per axis exceeds max_sigma (rad;
        then `next_try` is RETRY_TIME further along the history, which narrows it)."""
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
        # every start to its minimum: after a few iterations a wrong basin can still look best
        fits = [self._fit(_rotation(u * (2.0 * math.pi * i / YAW_GUESSES)) @ base, np.zeros(3), rates, h, index, n_B,
                          n_N, MAX_ITERATIONS, unbiased) for i in range(YAW_GUESSES)]
        best = min(fits, key=lambda fit: fit[2])
        # the best fit's mirror (below), which the starts about the first nadir need not reach
        fits += [self._fit(A, b, rates, h, index, n_B, n_N, MAX_ITERATIONS)
                 for A, b in _mirrors(best[0], best[1], np.concatenate([[0.0], np.cumsum(h)]), index, n_N)]
        best_cost = min(fit[2] for fit in fits)
        # the distinct minima that fit about as well with the gyro taken as exact (over minutes its
        # noise alone spoils such a fit by as much), each smoothed: the smoothing's fit decides
        candidates = []
        for A0, bias, cost in sorted(fits, key=lambda fit: fit[2]):
            if cost > CANDIDATE_RATIO * best_cost:
                break
            if all(_angle(A0 @ other.T) > DISTINCT_ANGLE for other, _ in candidates):
                candidates.append((A0, bias))
        smoothed = sorted((self._smooth(f.sigma_v, A0, bias, rates, h, index, n_B, n_N) for A0, bias in candidates),
                          key=lambda fit: fit[3])
        A, bias, cov, cost = smoothed[0]
        if any(_angle(other @ A.T) > DISTINCT_ANGLE and other_cost - cost < AMBIGUOUS_CHI2
               for other, _, _, other_cost in smoothed[1:]):
            self.next_try = self.span + RETRY_TIME
            return None
        if math.sqrt(max(cov[0, 0], cov[1, 1], cov[2, 2])) > max_sigma:
            self.next_try = self.span + RETRY_TIME
            return None
        f.initialize(rotations.dcm_to_quaternion(A.tolist()), math.sqrt(max(cov[0, 0], cov[1, 1], cov[2, 2])),
                     bias, self.sigma_bias0)
        f.P = cov  # the joint covariance, correlations between the attitude and the bias included
        return f

    def _smooth(self, sigma_v, A0, bias, rates, h, index, n_B, n_N):
        """Pass 2: the attitude at knots KNOT_SPACING apart and the bias, the knots linked by the
        gyro with its noise (sigma_v, rad/s^0.5), by Gauss-Newton from the batch's (A0, bias).
        Returns the last knot's (the last nadir sample's) attitude matrix, the bias, the joint
        covariance (6 x 6) of that attitude and the bias, and the fit's chi-square."""
        t = np.concatenate([[0.0], np.cumsum(h)])
        knots = [int(index[0])]
        for k in index[1:]:
            if t[k] - t[knots[-1]] >= KNOT_SPACING - 1e-9:
                knots.append(int(k))
        if knots[-1] != index[-1]:
            knots.append(int(index[-1]))
        knots = np.array(knots)
        n_knots = len(knots)
        seg = np.minimum(np.searchsorted(knots, index, side="right") - 1, n_knots - 1)  # each sample's knot
        D, _ = _integrate(rates, h, bias)
        A = np.einsum("jab,bc->jac", D[knots], A0)
        bias = np.array(bias, dtype=float)
        var_v = sigma_v ** 2
        # the measurement's noise per axis, and the gyro's between the sample and its knot
        w = 1.0 / ((max(self.nadir_sigma, 1e-6) / math.sqrt(2.0)) ** 2 + var_v * (t[index] - t[knots[seg]]))
        q_link = 1.0 / (var_v * np.diff(t[knots]))
        for _ in range(MAX_ITERATIONS):
            D, G = _integrate(rates, h, bias)
            M = np.einsum("kab,kcb->kac", D[index], D[knots[seg]])  # knot -> sample
            Gs = G[index] - M @ G[knots[seg]]
            pred = np.einsum("kab,kbc,kc->ka", M, A[seg], n_N)
            y = n_B - pred
            S = _skew(pred)
            Ja, Jb = S @ M, -(S @ Gs)
            diag = np.zeros((n_knots, 3, 3))
            cross = np.zeros((n_knots, 3, 3))  # knot x bias
            g_t = np.zeros((n_knots, 3))
            np.add.at(diag, seg, np.einsum("k,kia,kib->kab", w, Ja, Ja))
            np.add.at(cross, seg, np.einsum("k,kia,kib->kab", w, Ja, Jb))
            np.add.at(g_t, seg, np.einsum("k,kia,ki->ka", w, Ja, y))
            B = np.einsum("k,kia,kib->ab", w, Jb, Jb) + np.eye(3) / self.sigma_bias0 ** 2
            g_b = np.einsum("k,kia,ki->a", w, Jb, y) - bias / self.sigma_bias0 ** 2
            # the gyro between knots j and j+1: dtheta_j+1 - M_j dtheta_j + G_j db = noise - e_j
            k0, k1 = knots[:-1], knots[1:]
            Mj = np.einsum("jab,jcb->jac", D[k1], D[k0])
            Gj = G[k1] - Mj @ G[k0]
            e = _rotation_vectors(np.einsum("jab,jcb->jac", A[1:], Mj @ A[:-1]))
            qe = q_link[:, None] * e
            cost = (float(np.einsum("k,ki,ki->", w, y, y)) + float(np.einsum("j,ji,ji->", q_link, e, e))
                    + float(bias @ bias) / self.sigma_bias0 ** 2)
            diag[1:] += q_link[:, None, None] * np.eye(3)
            diag[:-1] += q_link[:, None, None] * np.eye(3)
            off = -q_link[:, None, None] * np.transpose(Mj, (0, 2, 1))  # block (j, j+1)
            cross[1:] += q_link[:, None, None] * Gj
            cross[:-1] -= q_link[:, None, None] * np.einsum("jba,jbc->jac", Mj, Gj)
            B = B + np.einsum("j,jba,jbc->ac", q_link, Gj, Gj)
            g_t[1:] -= qe
            g_t[:-1] += np.einsum("jba,jb->ja", Mj, qe)
            g_b = g_b - np.einsum("jba,jb->a", Gj, qe)
            d_theta, d_bias, cov = _solve_arrow(diag, off, cross, B, g_t, g_b)
            A = np.einsum("jab,jbc->jac", _rotations(d_theta), A)
            bias = bias + d_bias
            if np.abs(d_theta).max() < 1e-7 and np.abs(d_bias).max() < 1e-10:
                break
        return A[-1], bias, 0.5 * (cov + cov.T), cost


def _mirrors(A0, bias, t, index, n_N):
    """The two starts (A0', bias') of the mirror image of the fit (A0, bias). The nadirs lie in the
    orbit plane, turning at w about its normal o; turned half a turn about the mid-arc nadir
    n_m, the one at angle a from n_m goes to -a, and a further turn by 2a about o brings it back:
    the body A_k R_k with R_k = R_o(2 a_k) R_pi(n_m) sees every nadir as A_k does. For a body
    at rest in inertial space that is a body turning at 2 w about o, which a bias error of that
    size gives the gyro: the same fit exactly. Either sign of the bias error is returned."""
    # o and the angle swept from sample to sample: right for an arc of any length
    steps = np.cross(n_N[:-1], n_N[1:])
    normal = steps.sum(axis=0)
    if np.linalg.norm(normal) < 1e-9:
        return []
    o = normal / np.linalg.norm(normal)
    swept = np.arctan2(steps @ o, np.einsum("ki,ki->k", n_N[:-1], n_N[1:])).sum()
    w = swept / (t[index[-1]] - t[index[0]])
    mid = n_N[len(n_N) // 2]
    a0 = -w * t[index[len(n_N) // 2]]  # the nadir's angle at the history's start (t = 0) from n_m
    mirror = _rotation(o * 2.0 * a0).T @ (2.0 * np.outer(mid, mid) - np.eye(3))  # active R_o(2 a0) R_pi(n_m)
    start = A0 @ mirror
    spin = 2.0 * w * (A0 @ o)
    return [(start, bias + spin), (start, bias - spin)]


def _rotation_vectors(E):
    """The rotation vectors v (n, 3) of the attitude matrices E (n, 3, 3), E = _rotation(v)."""
    angle = np.arccos(np.clip((np.trace(E, axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0))
    s = np.sin(angle)
    scale = np.divide(angle, 2.0 * s, out=np.full_like(angle, 0.5), where=s > 1e-12)
    return scale[:, None] * np.stack([E[:, 1, 2] - E[:, 2, 1], E[:, 2, 0] - E[:, 0, 2], E[:, 0, 1] - E[:, 1, 0]], 1)


def _rotations(v):
    """_rotation of each row of v (n, 3), small or not."""
    angle = np.linalg.norm(v, axis=1)
    e = np.divide(v, angle[:, None], out=np.zeros_like(v), where=angle[:, None] > 0.0)
    c, s = np.cos(angle)[:, None, None], np.sin(angle)[:, None, None]
    return c * np.eye(3) + (1.0 - c) * np.einsum("ki,kj->kij", e, e) - s * _skew(e)


def _solve_arrow(diag, off, cross, B, g_t, g_b):
    """Gauss-Newton's normal equations [[T, C], [C^T, B]] [dtheta; db] = [g_t; g_b] with T block
    tridiagonal (3 x 3 blocks diag[j], off[j] = T[j, j+1]) and C's blocks cross[j]: block
    elimination along the chain, then the bias by its Schur complement. Returns dtheta (n, 3),
    db and the covariance (6 x 6) of the last knot's attitude and the bias, the inverse's blocks."""
    n = len(diag)
    rhs = np.zeros((n, 3, 7))  # columns: g_t, C, and the unit block of the last knot
    rhs[:, :, 0] = g_t
    rhs[:, :, 1:4] = cross
    rhs[-1, :, 4:7] = np.eye(3)
    inv = np.empty((n, 3, 3))
    inv[0] = np.linalg.inv(diag[0])
    for j in range(1, n):
        L = off[j - 1].T @ inv[j - 1]
        inv[j] = np.linalg.inv(diag[j] - L @ off[j - 1])
        rhs[j] -= L @ rhs[j - 1]
    X = np.empty_like(rhs)
    X[-1] = inv[-1] @ rhs[-1]
    for j in range(n - 2, -1, -1):
        X[j] = inv[j] @ (rhs[j] - off[j] @ X[j + 1])
    Xg, XC = X[:, :, 0], X[:, :, 1:4]
    S = B - np.einsum("jab,jac->bc", cross, XC)
    S_inv = np.linalg.inv(S)
    d_bias = S_inv @ (g_b - np.einsum("jab,ja->b", cross, Xg))
    d_theta = Xg - XC @ d_bias
    cov = np.empty((6, 6))
    cov[:3, :3] = X[-1, :, 4:7] + XC[-1] @ S_inv @ XC[-1].T
    cov[:3, 3:] = -XC[-1] @ S_inv
    cov[3:, :3] = cov[:3, 3:].T
    cov[3:, 3:] = S_inv
    return d_theta, d_bias, cov
