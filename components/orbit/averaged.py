"""Orbit-averaged (semi-analytic) lifetime model: mean elements under averaged drag, J2 secular
drift and short finite burns, fast enough for century-long lifetimes.

State (mean elements, non-singular for circular orbits):

    a,  ex = e cos(argp),  ey = e sin(argp),  i,  RAAN,  lam = argp + M  (mean argument of latitude)

Equatorial orbits are excluded (the node is undefined there): 1e-4 <= i <= pi - 1e-4.
Position and velocity are reconstructed from the mean elements by two-body formulae (the
given initial Keplerian elements are taken as mean elements; short-period J2 terms are not
added). With the eccentric longitude F = E + argp, solved from lam = F - ex sin F + ey cos F,
beta = 1 / (1 + sqrt(1 - e^2)) and r = a (1 - ex cos F - ey sin F), in the orbit plane
(x along the node, y 90 deg ahead in the direction of motion):

    x = a [(1 - beta ey^2) cos F + beta ex ey sin F - ex]
    y = a [(1 - beta ex^2) sin F + beta ex ey cos F - ey]
    xdot = n a^2 / r [beta ex ey cos F - (1 - beta ey^2) sin F]
    ydot = n a^2 / r [(1 - beta ex^2) cos F - beta ex ey sin F]

Gauss variational equations in these elements (u = argument of latitude, p = a (1 - e^2),
h = sqrt(mu p), eta = sqrt(1 - e^2), accelerations f_R, f_S, f_W radial / along-track / normal),
derived from the classical ones (Vallado, Fundamentals of Astrodynamics, Eq. 9-24) with
e cos nu = ex cos u + ey sin u and e sin nu = ex sin u - ey cos u; none divides by e:

    da/dt   = 2 a^2 / h [(ex sin u - ey cos u) f_R + p / r f_S]
    dex/dt  = 1/h [p sin u f_R + ((p + r) cos u + r ex) f_S + r ey sin u cot i f_W]
    dey/dt  = 1/h [-p cos u f_R + ((p + r) sin u + r ey) f_S - r ex sin u cot i f_W]
    di/dt   = r cos u / h f_W
    dRAAN/dt = r sin u / (h sin i) f_W
    dlam/dt = n - 1/h [(p (ex cos u + ey sin u) / (1 + eta) + 2 r eta) f_R
                       - (p + r)(ex sin u - ey cos u) / (1 + eta) f_S] - r sin u cot i / h f_W

Drag: f = -1/2 rho (Cd A / m) |v_rel| v_rel with v_rel = v - omega_atm x r (the atmosphere
co-rotates with the Earth), averaged over one orbit for every element (a, ex, ey, i, RAAN and
lam: the inclination keeps its small drag term from the atmosphere's rotation). The average is
the trapezoidal rule over N equally spaced eccentric longitudes F_k (spectrally accurate for a
periodic integrand), weighted by dM = (r / a) dF. Default N = 16: thesis lifetimes change by
< 1e-5 relative from N = 12 to 24 (Jacchia-Roberts, 525 km, 86.37 y). The density is the atmosphere kernel at each
node's actual 3D position at the current time (the orbit is averaged as a snapshot: within one
orbit the Sun moves 0.06 deg and the space weather is constant). The whole integration of a call
of advance_to (its RK4 steps, four averages each) is one call of a compiled function (numba, when
installed) with the model's kernel bound in; NRLMSIS's kernel calls pymsis for each node (slow:
N pymsis calls per evaluation, about 4 ms).

J2 secular drift (first order): dRAAN/dt and dargp/dt from components.orbit.elements.
j2_secular_rates, and dM/dt = n + 3/4 n J2 (R/p)^2 eta (2 - 3 sin^2 i) (Vallado Eq. 9-41;
orbit_elements has no M rate). argp's drift rotates (ex, ey); lam gets dargp/dt + dM/dt.

Thrust: the Gauss equations with the instantaneous thrust acceleration at the current position
(not averaged: burns are short), F_N / m, either F_N = A(q)^T F_B or, with `retrograde`, |F_B|
along -v. Inputs (thrust, attitude, mass) are held over a call of advance_to; the attitude
thrusters' running total of impulse (`impulse_B`) adds their mean force over the previous call
(propulsion.ImpulseWindow), except with retrograde.

Integration: classical RK4 on the six elements. Step size: at most `max_step` (default one
day), steps end on UTC midnights (the space-weather indices change there), at most
`max_da_step` of semi-major-axis change per step (default 1 km, so the final decay below
~250 km, days long, takes steps of hours), at most `thrust_step` (10 s) while thrust is on.
Re-entry: once the mean perigee altitude a (1 - e) - 6378136.3 m falls below
`reentry_altitude` the crossing time is located by secant iteration on the last step (to
< 1 s), the state is frozen there (`reentered`, `reentry_time`), and later calls only advance
the clock.
"""
import math

import numpy as np
from ..core.jit import function_of, loaded, njit
from ..core.constants import DAY, MU_EARTH, OMEGA_EARTH, R_EQ

from ..environment import geodesy
from ..environment.atmosphere import base, exponential, harris_priester, jacchia_roberts
from ..mission.neighbor import SPACECRAFT
from . import elements
from .propulsion import ImpulseWindow
from ..core import time_utils

J2 = elements.J2_EGM96
TWO_PI = 2.0 * math.pi
INC_MIN = 1e-4  # rad: the element set is singular for equatorial orbits


# ---- numba core -----------------------------------------------------------------------------
@njit(cache=True)
def _eccentric_longitude(lam, ex, ey):
    """F with lam = F - ex sin F + ey cos F (Newton)."""
    F = lam
    for _ in range(30):
        s, c = math.sin(F), math.cos(F)
        f = F - ex * s + ey * c - lam
        d = f / (1.0 - ex * c - ey * s)
        F -= d
        if abs(d) < 1e-14:
            break
    return F


@njit(cache=True)
def _plane_state(a, ex, ey, F, mu):
    """(x, y, xdot, ydot, r) in the orbit plane at eccentric longitude F."""
    e2 = ex * ex + ey * ey
    beta = 1.0 / (1.0 + math.sqrt(1.0 - e2))
    s, c = math.sin(F), math.cos(F)
    x = a * ((1.0 - beta * ey * ey) * c + beta * ex * ey * s - ex)
    y = a * ((1.0 - beta * ex * ex) * s + beta * ex * ey * c - ey)
    r = a * (1.0 - ex * c - ey * s)
    k = math.sqrt(mu / a) * a / r  # n a^2 / r
    xd = k * (beta * ex * ey * c - (1.0 - beta * ey * ey) * s)
    yd = k * ((1.0 - beta * ex * ex) * c - beta * ex * ey * s)
    return x, y, xd, yd, r


@njit(cache=True)
def _plane_axes(inc, raan):
    """P (toward the node) and Q (90 deg ahead in the orbit plane) and W (orbit normal) in N."""
    cO, sO, ci, si = math.cos(raan), math.sin(raan), math.cos(inc), math.sin(inc)
    P = (cO, sO, 0.0)
    Q = (-sO * ci, cO * ci, si)
    W = (sO * si, -cO * si, ci)
    return P, Q, W


@njit(cache=True)
def _gauss(a, ex, ey, inc, x, y, r, fR, fS, fW, mu, out, weight):
    """Adds weight x (da, dex, dey, di, draan, dlam - n) for accelerations fR, fS, fW (m/s^2)
    at the in-plane position (x, y), |r| = r, to out[0:6]."""
    e2 = ex * ex + ey * ey
    eta = math.sqrt(1.0 - e2)
    p = a * (1.0 - e2)
    h = math.sqrt(mu * p)
    cu, su = x / r, y / r
    esn = ex * su - ey * cu  # e sin(nu)
    ecn = ex * cu + ey * su  # e cos(nu)
    cot = math.cos(inc) / math.sin(inc)
    out[0] += weight * 2.0 * a * a / h * (esn * fR + p / r * fS)
    out[1] += weight * (p * su * fR + ((p + r) * cu + r * ex) * fS + r * ey * su * cot * fW) / h
    out[2] += weight * (-p * cu * fR + ((p + r) * su + r * ey) * fS - r * ex * su * cot * fW) / h
    out[3] += weight * r * cu / h * fW
    out[4] += weight * r * su / (h * math.sin(inc)) * fW
    out[5] += weight * (-(p * ecn / (1.0 + eta) + 2.0 * r * eta) * fR + (p + r) * esn / (1.0 + eta) * fS
                        - r * su * cot * fW) / h


@njit(cache=True)
def _nodes(y, mu, n_nodes):
    """Positions (n, 3), velocities (n, 3), in-plane x, y, r and weights r / (a n) of the quadrature
    nodes F_k = 2 pi k / n for the elements y = (a, ex, ey, i, raan, lam)."""
    a, ex, ey, inc, raan = y[0], y[1], y[2], y[3], y[4]
    P, Q, W = _plane_axes(inc, raan)
    R = np.empty((n_nodes, 3))
    V = np.empty((n_nodes, 3))
    geo = np.empty((n_nodes, 4))
    for k in range(n_nodes):
        F = 2.0 * math.pi * k / n_nodes
        x, yy, xd, yd, r = _plane_state(a, ex, ey, F, mu)
        for j in range(3):
            R[k, j] = x * P[j] + yy * Q[j]
            V[k, j] = xd * P[j] + yd * Q[j]
        geo[k, 0], geo[k, 1], geo[k, 2], geo[k, 3] = x, yy, r, r / (a * n_nodes)
    return R, V, geo


@njit(cache=True)
def _drag_sum(y, mu, bc, omega_atm, R, V, geo, rho):
    """Orbit-averaged Gauss rates of drag from the node densities rho (bc = Cd A / m)."""
    out = np.zeros(6)
    P, Q, W = _plane_axes(y[3], y[4])
    for k in range(R.shape[0]):
        rx, ry, rz = R[k, 0], R[k, 1], R[k, 2]
        vx = V[k, 0] + omega_atm * ry
        vy = V[k, 1] - omega_atm * rx
        vz = V[k, 2]
        vrel = math.sqrt(vx * vx + vy * vy + vz * vz)
        c = -0.5 * rho[k] * bc * vrel
        ax, ay, az = c * vx, c * vy, c * vz
        r = geo[k, 2]
        ur = (rx / r, ry / r, rz / r)
        us = (W[1] * ur[2] - W[2] * ur[1], W[2] * ur[0] - W[0] * ur[2], W[0] * ur[1] - W[1] * ur[0])
        fR = ax * ur[0] + ay * ur[1] + az * ur[2]
        fS = ax * us[0] + ay * us[1] + az * us[2]
        fW = ax * W[0] + ay * W[1] + az * W[2]
        _gauss(y[0], y[1], y[2], y[3], geo[k, 0], geo[k, 1], r, fR, fS, fW, mu, out, geo[k, 3])
    return out


@njit(cache=False)
def _drag_rates_kernel(y, jd, mu, bc, omega_atm, n_nodes, kernel, kernel_data):
    """Orbit-averaged drag rates with the atmosphere's numba kernel (one compiled call)."""
    R, V, geo = _nodes(y, mu, n_nodes)
    rho = np.empty(n_nodes)
    r = np.empty(3)
    for k in range(n_nodes):
        r[0], r[1], r[2] = R[k, 0], R[k, 1], R[k, 2]
        rho[k] = kernel(r, jd, kernel_data)
    return _drag_sum(y, mu, bc, omega_atm, R, V, geo, rho)


_SPECIALIZED = {}


def _drag_function(kernel):
    """_drag_rates_kernel with `kernel` bound at compile time. Passing a numba function as an
    argument makes every call resolve its type (about 30 us, ten times the quadrature itself);
    a closure over it compiles once per kernel and process."""
    f = _SPECIALIZED.get(function_of(kernel))
    if f is None:
        @njit(cache=False)
        def f(y, jd, mu, bc, omega_atm, n_nodes, kernel_data):
            return _drag_rates_kernel(y, jd, mu, bc, omega_atm, n_nodes, kernel, kernel_data)
        _SPECIALIZED[function_of(kernel)] = f
    return loaded(f)


@njit(cache=True)
def _j2_mean_anomaly(a, e, i, mu, j2, r_eq, two):
    """j2_mean_anomaly_rate; `two` is 2.0 given as a value: LLVM turns pow(x, 2.0) with a constant
    2.0 into x * x, which differs from libm's pow (Python's **) in the last bit about once in
    1,200 values."""
    n = math.sqrt(mu / a ** 3.0)
    p = a * (1.0 - e * e)
    si = math.sin(i)
    return 0.75 * n * j2 * (r_eq / p) ** two * math.sqrt(1.0 - e * e) * (2.0 - 3.0 * si * si)


# advance_to's parameters, one float64 array (prm[...]) for the compiled integration
_MU, _J2, _R_EQ, _OMEGA_ATM, _JD_EPOCH, _DAY_OFFSET, _MAX_STEP, _THRUST_STEP, _MAX_DA_STEP, _REENTRY, _TWO = range(11)
_NO_THRUST = np.zeros(3)
# the first argument of the ValueError the compiled integration raises when the elements leave
# the closed-orbit domain (advance_to words it; numba cannot format a message)
_OUTSIDE_DOMAIN = "mean elements left the closed-orbit domain"


@njit
def _rates_kernel(y, t, prm, bc, n_nodes, drag, f_N, retro, thrust_on, kernel, kernel_data):
    """d/dt of the elements y at time t: drag (when `drag`), J2, the mean motion and the thrust
    (f_N, retro as _thrust_rates', when thrust_on)."""
    if not (y[0] > 0.0 and y[1] * y[1] + y[2] * y[2] < 1.0):
        raise ValueError(_OUTSIDE_DOMAIN, y[0], y[1], y[2], t)
    mu = prm[_MU]
    if drag:
        d = _drag_rates_kernel(y, prm[_JD_EPOCH] + t / DAY, mu, bc, prm[_OMEGA_ATM], n_nodes, kernel, kernel_data)
    else:
        d = np.zeros(6)
    draan, dargp, dM = 0.0, 0.0, 0.0
    if prm[_J2] != 0.0:
        e = math.hypot(y[1], y[2])  # the C library's; CPython's differs by an ulp in 1 value of 700
        draan, dargp = elements.j2_secular_core(y[0], e, y[3], mu, prm[_J2], prm[_R_EQ])
        dM = _j2_mean_anomaly(y[0], e, y[3], mu, prm[_J2], prm[_R_EQ], prm[_TWO])
    d[1] -= y[2] * dargp
    d[2] += y[1] * dargp
    d[4] += draan
    d[5] += math.sqrt(mu / y[0] ** 3.0) + dargp + dM
    if thrust_on:
        thrust = _thrust_rates(y, mu, f_N, retro)
        for j in range(6):
            d[j] += thrust[j]
    return d


@njit
def _rk4_kernel(y, t, h, k1, prm, bc, n_nodes, drag, f_N, retro, thrust_on, kernel, kernel_data):
    """One classical RK4 step of h from (t, y) with k1 = the rates there: numpy's operations on the
    six elements, in the same order (the same bits), written as loops."""
    total = k1.copy()  # k1 + 2 k2 + 2 k3 + k4, summed in that order
    k = k1
    stage_y = np.empty(6)
    for stage in range(3):
        c = h if stage == 2 else 0.5 * h
        for j in range(6):
            stage_y[j] = y[j] + c * k[j]
        k = _rates_kernel(stage_y, t + c, prm, bc, n_nodes, drag, f_N, retro, thrust_on, kernel, kernel_data)
        weight = 1.0 if stage == 2 else 2.0  # 1.0 * k is k
        for j in range(6):
            total[j] += weight * k[j]
    sixth = h / 6.0
    out = np.empty(6)
    for j in range(6):
        out[j] = y[j] + sixth * total[j]
    return out


@njit(cache=True)
def _perigee_margin(y, reentry_altitude):
    return y[0] * (1.0 - math.hypot(y[1], y[2])) - R_EQ - reentry_altitude


@njit
def _advance_kernel(y, t, t_end, min_step, prm, bc, n_nodes, drag, f_N, retro, thrust_on, kernel, kernel_data):
    """OrbitAveraged.advance_to's integration from (t, y) toward t_end: RK4 steps (module
    docstring) while more than min_step is left. Returns (y, t reached, drag evaluations, re-entry
    time or -1.0): at re-entry the state there, located by secant iteration on the step's length
    (to < 1 s or 1 m)."""
    evaluations = 0
    per_rates = 1 if drag else 0
    while t_end - t > min_step:
        h = min(t_end - t, prm[_MAX_STEP])
        to_midnight = DAY - (prm[_DAY_OFFSET] + t) % DAY
        if to_midnight > 1e-3:
            h = min(h, to_midnight)
        if thrust_on:
            h = min(h, prm[_THRUST_STEP])
        k1 = _rates_kernel(y, t, prm, bc, n_nodes, drag, f_N, retro, thrust_on, kernel, kernel_data)
        if k1[0] != 0.0:
            h = min(h, prm[_MAX_DA_STEP] / abs(k1[0]))
        y1 = _rk4_kernel(y, t, h, k1, prm, bc, n_nodes, drag, f_N, retro, thrust_on, kernel, kernel_data)
        evaluations += 4 * per_rates
        if _perigee_margin(y1, prm[_REENTRY]) < 0.0:
            lo, glo, hi, ghi = 0.0, _perigee_margin(y, prm[_REENTRY]), h, _perigee_margin(y1, prm[_REENTRY])
            tau, yt = hi, y1
            for _ in range(40):
                tau = lo + (hi - lo) * glo / (glo - ghi)
                tau = min(max(tau, lo + 1e-3 * (hi - lo)), hi - 1e-3 * (hi - lo))
                yt = _rk4_kernel(y, t, tau, k1, prm, bc, n_nodes, drag, f_N, retro, thrust_on, kernel, kernel_data)
                evaluations += 3 * per_rates
                g = _perigee_margin(yt, prm[_REENTRY])
                if g < 0.0:
                    hi, ghi = tau, g
                else:
                    lo, glo = tau, g
                if hi - lo < 1.0 or abs(g) < 1.0:
                    break
            yt[4] %= TWO_PI
            yt[5] %= TWO_PI
            return yt, t + tau, evaluations, t + tau
        t, y = t + h, y1
        y[4] %= TWO_PI
        y[5] %= TWO_PI
    return y, t, evaluations, -1.0


# _advance_kernel with each of the product's atmosphere kernels bound in, cached like every kernel
# here (components.core.jit): a kernel named as a module's attribute in a module's function is
# cached with it, a closure's is not (it took 2-4 s to compile in every process; the drag closure
# of drag_rates, which the integration called before, 1 s)
@njit(cache=True)
def _advance_jacchia_roberts(y, t, t_end, min_step, prm, bc, n_nodes, drag, f_N, retro, thrust_on, kernel_data):
    return _advance_kernel(y, t, t_end, min_step, prm, bc, n_nodes, drag, f_N, retro, thrust_on,
                           jacchia_roberts.jacchia_roberts_kernel, kernel_data)


@njit(cache=True)
def _advance_harris_priester(y, t, t_end, min_step, prm, bc, n_nodes, drag, f_N, retro, thrust_on, kernel_data):
    return _advance_kernel(y, t, t_end, min_step, prm, bc, n_nodes, drag, f_N, retro, thrust_on,
                           harris_priester.harris_priester_kernel, kernel_data)


@njit(cache=True)
def _advance_exponential(y, t, t_end, min_step, prm, bc, n_nodes, drag, f_N, retro, thrust_on, kernel_data):
    return _advance_kernel(y, t, t_end, min_step, prm, bc, n_nodes, drag, f_N, retro, thrust_on,
                           exponential.exponential_kernel, kernel_data)


@njit(cache=True)
def _advance_without_drag(y, t, t_end, min_step, prm, bc, n_nodes, drag, f_N, retro, thrust_on, kernel_data):
    return _advance_kernel(y, t, t_end, min_step, prm, bc, n_nodes, drag, f_N, retro, thrust_on,
                           base.vacuum_kernel, kernel_data)


_ADVANCE = {function_of(k): f for k, f in ((jacchia_roberts.jacchia_roberts_kernel, _advance_jacchia_roberts),
                                           (harris_priester.harris_priester_kernel, _advance_harris_priester),
                                           (exponential.exponential_kernel, _advance_exponential),
                                           (base.vacuum_kernel, _advance_without_drag))}


def _advance_function(kernel):
    """_advance_kernel with the atmosphere's `kernel` bound in: cached for the product's kernels,
    else (NRLMSIS, a user's kernel) a closure compiled once per kernel and process, as _drag_function."""
    f = _ADVANCE.get(function_of(kernel))
    if f is None:
        @njit(cache=False)
        def f(y, t, t_end, min_step, prm, bc, n_nodes, drag, f_N, retro, thrust_on, kernel_data):
            return _advance_kernel(y, t, t_end, min_step, prm, bc, n_nodes, drag, f_N, retro, thrust_on,
                                   kernel, kernel_data)
        _ADVANCE[function_of(kernel)] = f
    return loaded(f)


@njit(cache=True)
def _state_N(y, mu):
    """(r_N, v_N) arrays of the mean elements y (two-body)."""
    F = _eccentric_longitude(y[5], y[1], y[2])
    x, yy, xd, yd, r = _plane_state(y[0], y[1], y[2], F, mu)
    P, Q, W = _plane_axes(y[3], y[4])
    rv = np.empty(3)
    vv = np.empty(3)
    for j in range(3):
        rv[j] = x * P[j] + yy * Q[j]
        vv[j] = xd * P[j] + yd * Q[j]
    return rv, vv


@njit(cache=True)
def _thrust_rates(y, mu, f_N, retro_mag):
    """Gauss rates (without n) of the thrust acceleration at the current position: f_N (m/s^2,
    in N), or, when retro_mag > 0, retro_mag along -v."""
    F = _eccentric_longitude(y[5], y[1], y[2])
    x, yy, xd, yd, r = _plane_state(y[0], y[1], y[2], F, mu)
    P, Q, W = _plane_axes(y[3], y[4])
    if retro_mag > 0.0:
        v = math.sqrt(xd * xd + yd * yd)  # in-plane components: along -v
        fx, fy = -retro_mag * xd / v, -retro_mag * yd / v
        fR = (fx * x + fy * yy) / r
        fS = (-fx * yy + fy * x) / r
        fW = 0.0
    else:
        ax = f_N[0] * P[0] + f_N[1] * P[1] + f_N[2] * P[2]  # components along P, Q, W
        ay = f_N[0] * Q[0] + f_N[1] * Q[1] + f_N[2] * Q[2]
        fW = f_N[0] * W[0] + f_N[1] * W[1] + f_N[2] * W[2]
        fR = (ax * x + ay * yy) / r
        fS = (-ax * yy + ay * x) / r
    out = np.zeros(6)
    _gauss(y[0], y[1], y[2], y[3], x, yy, r, fR, fS, fW, mu, out, 1.0)
    return out


def quaternion_to_dcm(q):
    """A(q) (N -> B) of the scalar-last quaternion q (normalized here), thesis Eq. 20."""
    q1, q2, q3, q4 = q
    n = math.sqrt(q1 * q1 + q2 * q2 + q3 * q3 + q4 * q4)
    if not (math.isfinite(n) and n > 0.0):
        raise ValueError(f"q_BN {list(q)} must be a finite, non-zero quaternion")
    q1, q2, q3, q4 = q1 / n, q2 / n, q3 / n, q4 / n
    return np.array([
        [q1 * q1 - q2 * q2 - q3 * q3 + q4 * q4, 2 * (q1 * q2 + q3 * q4), 2 * (q1 * q3 - q2 * q4)],
        [2 * (q1 * q2 - q3 * q4), -q1 * q1 + q2 * q2 - q3 * q3 + q4 * q4, 2 * (q2 * q3 + q1 * q4)],
        [2 * (q1 * q3 + q2 * q4), 2 * (q2 * q3 - q1 * q4), -q1 * q1 - q2 * q2 + q3 * q3 + q4 * q4]])


def j2_mean_anomaly_rate(a, e, i, mu=MU_EARTH, j2=J2, r_eq=R_EQ):
    """First-order J2 secular part of dM/dt (rad/s, without n): 3/4 n J2 (R/p)^2 eta (2 - 3 sin^2 i)."""
    return _j2_mean_anomaly(float(a), float(e), float(i), float(mu), float(j2), float(r_eq), 2.0)


# ---- the model ---------------------------------------------------------------------------------
def _finite(name, value, lo=None, hi=None, lo_open=False, unit=""):
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} = {value!r} must be a finite number{unit}") from None
    ok = math.isfinite(value)
    if ok and lo is not None:
        ok = value > lo if lo_open else value >= lo
    if ok and hi is not None:
        ok = value <= hi
    if not ok:
        lo_txt = "" if lo is None else ("> " if lo_open else ">= ") + f"{lo:g}"
        hi_txt = "" if hi is None else f"<= {hi:g}"
        rng = " and ".join(t for t in (lo_txt, hi_txt) if t)
        raise ValueError(f"{name} = {value!r} must be finite{' and ' + rng if rng else ''}{unit}")
    return value


class OrbitAveraged:
    """Mean-element lifetime propagator (see the module docstring).

    `density_model`: a components.environment.atmosphere model (.density, .kernel, .kernel_data), or None
    for no drag (density 0).
    Time t is seconds since `epoch`; advance_to(t, ...) integrates to t exactly."""

    def __init__(self, density_model, epoch=time_utils.DEFAULT_EPOCH, sma0=R_EQ + 420e3, ecc0=0.0,
                 inc0=math.radians(51.6), raan0=0.0, argp0=0.0, ta0=0.0, Cd=SPACECRAFT.Cd,
                 area=SPACECRAFT.drag_area,
                 reentry_altitude=250e3, mu=MU_EARTH, j2=J2, r_eq=R_EQ, omega_atm=OMEGA_EARTH,
                 quadrature_nodes=16, max_step=DAY, max_da_step=1000.0, thrust_step=10.0, t0=0.0):
        self.jd_epoch = time_utils.julian_date(epoch)  # validates the epoch string
        self.epoch = epoch
        self.mu = _finite("mu", mu, 0.0, lo_open=True, unit=" m3/s2")
        self.r_eq = _finite("r_eq", r_eq, 0.0, lo_open=True, unit=" m")
        self.j2 = _finite("j2", j2, 0.0, 0.01)
        self.omega_atm = _finite("omega_atm", omega_atm, unit=" rad/s")
        self.Cd = _finite("Cd", Cd, 0.0, 10.0)
        self.area = _finite("area", area, 0.0, unit=" m2")
        self.reentry_altitude = _finite("reentry_altitude", reentry_altitude, 0.0, unit=" m")
        n_nodes = quadrature_nodes
        if isinstance(n_nodes, bool) or int(n_nodes) != n_nodes or not 8 <= int(n_nodes) <= 512:
            raise ValueError(f"quadrature_nodes = {quadrature_nodes!r} must be an integer in [8, 512]")
        self.n_nodes = int(n_nodes)
        self.max_step = _finite("max_step", max_step, 0.0, lo_open=True, unit=" s")
        self.max_da_step = _finite("max_da_step", max_da_step, 0.0, lo_open=True, unit=" m")
        self.thrust_step = _finite("thrust_step", thrust_step, 0.0, lo_open=True, unit=" s")
        a = _finite("sma0", sma0, 0.0, lo_open=True, unit=" m")
        e = _finite("ecc0", ecc0, 0.0, unit="")
        if not e < 1.0:
            raise ValueError(f"ecc0 = {e!r} must be in [0, 1) (closed orbits only)")
        inc = _finite("inc0", inc0, INC_MIN, math.pi - INC_MIN,
                      unit=" rad (equatorial orbits are singular for this element set)")
        raan = _finite("raan0", raan0, unit=" rad")
        argp = _finite("argp0", argp0, unit=" rad")
        ta = _finite("ta0", ta0, unit=" rad")
        perigee_alt = a * (1.0 - e) - R_EQ
        if perigee_alt < self.reentry_altitude:
            raise ValueError(f"initial perigee altitude sma0 (1 - ecc0) - {R_EQ} m = {perigee_alt!r} m is below "
                             f"reentry_altitude = {self.reentry_altitude!r} m")
        if density_model is not None:
            for name in ("kernel", "kernel_data", "density"):
                if not hasattr(density_model, name):
                    raise ValueError(f"density_model {density_model!r} lacks .{name} "
                                     "(components.environment.atmosphere model)")
        self.atmosphere = density_model  # None: no drag
        M = elements.mean_from_true(ta, e)
        self.y = np.array([a, e * math.cos(argp), e * math.sin(argp), inc, raan % TWO_PI, (argp + M) % TWO_PI])
        self.t = time_utils.check_time(t0, "start time")
        # seconds of the UTC day at t = 0, for steps that end on UTC midnights
        self._day_offset = ((self.jd_epoch - 0.5) % 1.0) * DAY
        self.reentered = False
        self.reentry_time = None
        self.evaluations = 0  # drag-average evaluations (for the bench)
        self.impulse = ImpulseWindow()  # the attitude thrusters' force (advance_to's impulse_B)
        self._out_cache = None

    # ---- elements --------------------------------------------------------------------------
    @property
    def sma(self):
        return float(self.y[0])

    @property
    def ecc(self):
        return math.hypot(self.y[1], self.y[2])

    @property
    def inclination(self):
        return float(self.y[3])

    @property
    def raan(self):
        return float(self.y[4])

    @property
    def argp(self):
        return math.atan2(self.y[2], self.y[1]) % TWO_PI if self.ecc > 0.0 else 0.0

    @property
    def mean_arg_latitude(self):
        return float(self.y[5])

    @property
    def perigee_altitude(self):
        return self.sma * (1.0 - self.ecc) - R_EQ

    @property
    def apogee_altitude(self):
        return self.sma * (1.0 + self.ecc) - R_EQ

    def jd(self, t=None):
        return self.jd_epoch + (self.t if t is None else t) / DAY

    # ---- rates -----------------------------------------------------------------------------
    def drag_rates(self, y, t, mass):
        """Orbit-averaged drag rates (a, ex, ey, i, RAAN, lam) at time t (s) for the total mass (kg)."""
        if self.atmosphere is None:
            return np.zeros(6)
        bc = self.Cd * self.area / mass
        jd = self.jd(t)
        self.evaluations += 1
        return _drag_function(self.atmosphere.kernel)(y, jd, self.mu, bc, self.omega_atm, self.n_nodes,
                                                      self.atmosphere.kernel_data)

    def thrust_acceleration(self, F_thrust_B, q_BN=(0.0, 0.0, 0.0, 1.0), retrograde=False, mass=SPACECRAFT.mass):
        """None when the thrust is zero, else (f_N m/s^2, retro magnitude m/s^2) for _thrust_rates."""
        F = np.array([float(x) for x in F_thrust_B])
        if F.shape != (3,) or not np.all(np.isfinite(F)):
            raise ValueError(f"F_thrust_B {list(F_thrust_B)} must be 3 finite numbers (N)")
        mag = float(np.linalg.norm(F))
        if mag == 0.0:
            return None
        if retrograde:
            return np.zeros(3), mag / mass
        return quaternion_to_dcm(q_BN).T @ F / mass, 0.0

    def advance_to(self, t_end, F_thrust_B=(0.0, 0.0, 0.0), q_BN=(0.0, 0.0, 0.0, 1.0), retrograde=False,
                   mass=SPACECRAFT.mass, impulse_B=None):
        """Integrate to t_end (s since the epoch) with the inputs held; stops integrating at
        re-entry (the clock still moves to t_end). impulse_B: the attitude thrusters' running total
        of impulse (N.s, B), whose mean force over the previous step is added to F_thrust_B
        (propulsion.ImpulseWindow; not with retrograde)."""
        t_end = time_utils.check_time(t_end, "time")
        mass = float(mass)
        if not (math.isfinite(mass) and mass > 0.0):
            raise ValueError(f"mass = {mass!r} kg must be finite and > 0")
        if t_end < self.t:
            raise ValueError(f"time {t_end!r} s is before the model time {self.t!r} s (no backward steps)")
        if impulse_B is not None:  # after the checks: a refused call leaves the window as it was
            extra = self.impulse.force(impulse_B, t_end - self.t)
            if extra != (0.0, 0.0, 0.0) and not retrograde:
                F_thrust_B = tuple(float(f) + e for f, e in zip(F_thrust_B, extra))
        thrust = self.thrust_acceleration(F_thrust_B, q_BN, retrograde, mass)
        self._out_cache = None
        if not self.reentered:
            f_N, retro = (_NO_THRUST, 0.0) if thrust is None else thrust
            drag = self.atmosphere is not None
            kernel, data = (self.atmosphere.kernel, self.atmosphere.kernel_data) if drag else (base.vacuum_kernel, ())
            prm = np.array([self.mu, self.j2, self.r_eq, self.omega_atm, self.jd_epoch, self._day_offset,
                            self.max_step, self.thrust_step, self.max_da_step, self.reentry_altitude, 2.0])
            # a step shorter than the rounding of the time is no step; anything longer is integrated
            # (a relative tolerance would drop the 0.1 s steps of a run years after its epoch)
            min_step = 64.0 * math.ulp(max(1.0, abs(t_end)))
            try:
                y, _, evaluations, reentry_time = _advance_function(kernel)(
                    self.y, self.t, t_end, min_step, prm, self.Cd * self.area / mass, self.n_nodes, drag,
                    f_N, retro, thrust is not None, data)
            except ValueError as err:
                if err.args[:1] != (_OUTSIDE_DOMAIN,):
                    raise
                a, ex, ey, t = err.args[1:]
                e = math.hypot(ex, ey)
                raise ValueError(f"{_OUTSIDE_DOMAIN} (a = {a!r} m, e = {e!r}) at t = {t!r} s") from None
            self.y = y
            self.evaluations += evaluations
            if reentry_time >= 0.0:
                self.reentered, self.reentry_time = True, reentry_time
        self.t = t_end

    # ---- outputs ---------------------------------------------------------------------------
    def state_vectors(self):
        """(r_BN_N, v_BN_N) numpy arrays (m, m/s) from the mean elements (two-body)."""
        if self._out_cache is None:
            r, v = _state_N(self.y, self.mu)
            jd = self.jd(self.reentry_time if self.reentered else self.t)
            lat, lon, alt = geodesy.geodetic_from_inertial(tuple(r), jd)
            self._out_cache = (r, v, lat, lon, alt, None, jd)
        return self._out_cache[0], self._out_cache[1]

    def geodetic(self):
        """(latitude rad, east longitude rad, geodetic altitude m) of the current position."""
        self.state_vectors()
        return self._out_cache[2:5]

    def density(self):
        """Density (kg/m^3) at the current position and time (at re-entry: the frozen one)."""
        self.state_vectors()
        c = self._out_cache
        if c[5] is None:
            rho = 0.0 if self.atmosphere is None else self.atmosphere.density(c[0], c[6])
            self._out_cache = c[:5] + (rho, c[6])
        return self._out_cache[5]

    def get_state(self):
        return {"t": self.t, "y": [float(x) for x in self.y], "reentered": self.reentered,
                "reentry_time": self.reentry_time, "evaluations": self.evaluations,
                "impulse": self.impulse.get_state()}

    def set_state(self, state):
        self.t = float(state["t"])
        self.y = np.array(state["y"], dtype=float)
        self.reentered = bool(state["reentered"])
        self.reentry_time = state["reentry_time"]
        self.evaluations = int(state["evaluations"])
        if "impulse" in state:  # states saved before the thrusters' force reached the orbit carry none
            self.impulse.set_state(state["impulse"])
        self._out_cache = None
