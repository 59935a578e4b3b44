"""Keplerian elements, Kepler's equation and two-body propagation (units m, s, rad).

Elements: semi-major axis a, eccentricity e, inclination i, right ascension of the ascending node
RAAN, argument of perigee argp, true anomaly nu (thesis Table 3 uses the same six). Frame: N.

    r = R3(-RAAN) R1(-i) R3(-argp) r_perifocal,   r_perifocal = p / (1 + e cos nu) [cos nu, sin nu, 0]
    v = ... sqrt(mu / p) [-sin nu, e + cos nu, 0],  p = a (1 - e^2)         (Vallado, Alg. 10)

Singular cases (no NaN, and `kepler_to_cartesian(*cartesian_to_kepler(r, v))` reproduces r, v):
- circular (e < ECC_TOL): the perigee is undefined; argp is set to 0 and nu is the argument of
  latitude u (angle from the ascending node to r, in the direction of motion);
- equatorial (sin i < INC_TOL): the node is undefined; RAAN is set to 0 and the x axis of N plays
  the node's role, so argp is the longitude of perigee and (if also circular) nu the true
  longitude, both measured in the direction of motion (for i = pi that is clockwise about +z).

Constants: mu = 398600.4415 km^3/s^2 (the thesis' value, Eq. 2; EGM96), R_eq = 6378.1363 km
(thesis Sec. 3.2; EGM96), J2 = -sqrt(5) C20bar with EGM96 C20bar = -0.484165371736e-3.

Errors: ValueError for a <= 0, e < 0 or e >= 1 (only closed orbits are supported; a state with
non-negative energy has no semi-major axis here), i outside [0, pi], non-finite input, mu <= 0.
"""
import math

import numpy as np

from ..core.constants import MU_EARTH, R_EQ
from ..core.jit import njit

J2_EGM96 = -math.sqrt(5.0) * -0.484165371736e-3  # = 1.0826266835531513e-3

ECC_TOL = 1e-11  # below this an orbit is treated as circular
INC_TOL = 1e-11  # sin(i) below this: equatorial
TWO_PI = 2.0 * math.pi


def _check_mu(mu):
    mu = float(mu)
    if not (math.isfinite(mu) and mu > 0.0):
        raise ValueError(f"mu = {mu!r} must be a finite positive gravitational parameter (m^3/s^2)")
    return mu


def _check_a_e(a, e):
    a, e = float(a), float(e)
    if not (math.isfinite(a) and a > 0.0):
        raise ValueError(f"semi-major axis a = {a!r} m must be finite and > 0 (closed orbits only)")
    if not (math.isfinite(e) and 0.0 <= e < 1.0):
        raise ValueError(f"eccentricity e = {e!r} must be in [0, 1) (closed orbits only)")
    return a, e


def _vec3(x, name):
    x = np.asarray(x, dtype=float).reshape(-1)
    if x.shape != (3,) or not np.all(np.isfinite(x)):
        raise ValueError(f"{name} = {x!r} must be 3 finite numbers")
    return x


def wrap_2pi(x):
    """x mapped to [0, 2 pi)."""
    y = math.fmod(x, TWO_PI)
    if y < 0.0:
        y += TWO_PI
    return 0.0 if y >= TWO_PI else y


# ---- anomalies -------------------------------------------------------------------------------
def solve_kepler(M, e, tol=1e-15, max_iter=50):
    """Eccentric anomaly E (rad) with E - e sin E = M, 0 <= e < 1 (Newton from Danby's start).

    E is returned on the same revolution as M (E - M is in [-e, e])."""
    e = float(e)
    if not (0.0 <= e < 1.0):
        raise ValueError(f"eccentricity e = {e!r} must be in [0, 1) for Kepler's equation")
    M = float(M)
    if not math.isfinite(M):
        raise ValueError(f"mean anomaly M = {M!r} must be finite")
    if e == 0.0:
        return M
    k = math.floor(M / TWO_PI + 0.5)
    m = M - k * TWO_PI  # in [-pi, pi)
    E = m + 0.85 * e * math.copysign(1.0, math.sin(m)) if m != 0.0 else 0.0
    for _ in range(max_iter):
        f = E - e * math.sin(E) - m
        dE = -f / (1.0 - e * math.cos(E))
        E += dE
        if abs(dE) <= tol * max(1.0, abs(E)):
            break
    return E + k * TWO_PI


def true_from_eccentric(E, e):
    return 2.0 * math.atan2(math.sqrt(1.0 + e) * math.sin(E / 2.0), math.sqrt(1.0 - e) * math.cos(E / 2.0))


def eccentric_from_true(nu, e):
    return 2.0 * math.atan2(math.sqrt(1.0 - e) * math.sin(nu / 2.0), math.sqrt(1.0 + e) * math.cos(nu / 2.0))


def mean_from_true(nu, e):
    """Mean anomaly (rad, in (-pi, pi]) of the true anomaly nu."""
    _check_a_e(1.0, e)
    E = eccentric_from_true(nu, e)
    return E - e * math.sin(E)


def true_from_mean(M, e):
    """True anomaly (rad, in (-pi, pi]) of the mean anomaly M."""
    return true_from_eccentric(solve_kepler(M, e), e)


def mean_motion(a, mu=MU_EARTH):
    """n = sqrt(mu / a^3) (rad/s)."""
    a, _ = _check_a_e(a, 0.0)
    return math.sqrt(_check_mu(mu) / a ** 3)


def period(a, mu=MU_EARTH):
    """T = 2 pi sqrt(a^3 / mu) (s), thesis Eq. 67."""
    return TWO_PI / mean_motion(a, mu)


# ---- elements <-> Cartesian ------------------------------------------------------------------
def kepler_to_cartesian(a, e, i, raan, argp, nu, mu=MU_EARTH):
    """(r_N, v_N) numpy arrays (m, m/s) of the classical elements (m, 1, rad)."""
    a, e = _check_a_e(a, e)
    mu = _check_mu(mu)
    i = float(i)
    if not (math.isfinite(i) and 0.0 <= i <= math.pi):
        raise ValueError(f"inclination i = {i!r} rad must be in [0, pi]")
    for name, x in (("raan", raan), ("argp", argp), ("nu", nu)):
        if not math.isfinite(float(x)):
            raise ValueError(f"{name} = {x!r} must be a finite angle (rad)")
    p = a * (1.0 - e * e)
    cn, sn = math.cos(nu), math.sin(nu)
    rmag = p / (1.0 + e * cn)
    rp = (rmag * cn, rmag * sn)
    sq = math.sqrt(mu / p)
    vp = (-sq * sn, sq * (e + cn))
    cO, sO = math.cos(raan), math.sin(raan)
    ci, si = math.cos(i), math.sin(i)
    cw, sw = math.cos(argp), math.sin(argp)
    # columns of R3(-O) R1(-i) R3(-w): P (perigee direction) and Q
    P = (cO * cw - sO * ci * sw, sO * cw + cO * ci * sw, si * sw)
    Q = (-cO * sw - sO * ci * cw, -sO * sw + cO * ci * cw, si * cw)
    r = np.array([P[k] * rp[0] + Q[k] * rp[1] for k in range(3)])
    v = np.array([P[k] * vp[0] + Q[k] * vp[1] for k in range(3)])
    return r, v


def cartesian_to_kepler(r, v, mu=MU_EARTH):
    """(a, e, i, raan, argp, nu) of an N state (m, m/s); angles in [0, 2 pi) (i in [0, pi]).

    See the module docstring for the circular and equatorial conventions."""
    r = _vec3(r, "r")
    v = _vec3(v, "v")
    mu = _check_mu(mu)
    rmag = math.sqrt(r @ r)
    if rmag == 0.0:
        raise ValueError("r = [0, 0, 0]: the position must be non-zero")
    v2 = float(v @ v)
    energy = 0.5 * v2 - mu / rmag
    if not energy < 0.0:
        raise ValueError(f"state with specific energy {energy!r} J/kg >= 0 is not a closed orbit "
                         "(a <= 0 or e >= 1); only elliptic orbits are supported")
    a = -mu / (2.0 * energy)
    h = np.cross(r, v)
    hmag = math.sqrt(h @ h)
    if hmag == 0.0:
        raise ValueError("r and v are parallel (rectilinear orbit, e = 1): not supported")
    evec = ((v2 - mu / rmag) * r - float(r @ v) * v) / mu
    e = math.sqrt(evec @ evec)
    if e >= 1.0:
        raise ValueError(f"eccentricity e = {e!r} >= 1: only closed orbits are supported")
    hhat = h / hmag
    nxy = math.hypot(h[0], h[1])  # |z x h|
    i = math.atan2(nxy, h[2])  # (acos(h_z/|h|) would lose precision near 0 and pi)
    if nxy > INC_TOL * hmag:
        nhat = np.array([-h[1], h[0], 0.0]) / nxy
        raan = wrap_2pi(math.atan2(nhat[1], nhat[0]))
    else:  # equatorial: the x axis takes the node's place
        nhat = np.array([1.0, 0.0, 0.0])
        raan = 0.0
    qhat = np.cross(hhat, nhat)
    u = math.atan2(float(r @ qhat), float(r @ nhat))  # argument of latitude (or true longitude)
    if e > ECC_TOL:
        argp = wrap_2pi(math.atan2(float(evec @ qhat), float(evec @ nhat)))
        nu = wrap_2pi(u - argp)
    else:
        argp = 0.0
        nu = wrap_2pi(u)
    return a, e, i, raan, argp, nu


# ---- quantities from a state (cheap scalar code: used every communication step) ------------
def osculating_sma(r, v, mu=MU_EARTH):
    """a = 1 / (2/|r| - |v|^2/mu) (m); ValueError if the state is not a closed orbit."""
    rm = math.sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2])
    inv = 2.0 / rm - (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) / mu
    if not inv > 0.0:
        raise ValueError("state is not a closed orbit (energy >= 0, a <= 0)")
    return 1.0 / inv


def osculating_ecc(r, v, mu=MU_EARTH):
    """|e| from the eccentricity vector e = ((v^2 - mu/r) r - (r.v) v) / mu."""
    rm = math.sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2])
    v2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2]
    rv = r[0] * v[0] + r[1] * v[1] + r[2] * v[2]
    c = v2 - mu / rm
    ex, ey, ez = ((c * r[k] - rv * v[k]) / mu for k in range(3))
    return math.sqrt(ex * ex + ey * ey + ez * ez)


def perigee_apogee_radii(r, v, mu=MU_EARTH):
    """(a (1 - e), a (1 + e)) in m for the osculating orbit."""
    a = osculating_sma(r, v, mu)
    e = osculating_ecc(r, v, mu)
    if e >= 1.0:
        raise ValueError(f"eccentricity e = {e!r} >= 1: only closed orbits are supported")
    return a * (1.0 - e), a * (1.0 + e)


# ---- analytic two-body propagation -----------------------------------------------------------
def kepler_propagate(r, v, dt, mu=MU_EARTH):
    """Two-body state (r, v) after dt seconds (either sign), by Lagrange f and g coefficients with
    the eccentric-anomaly change dE (Vallado Sec. 2.3 / Battin): no elements are formed, so
    circular and equatorial orbits need no special case.

        n dt = dE - (1 - r0/a) sin dE + (r0.v0 / sqrt(mu a)) (1 - cos dE)
        f = 1 - a/r0 (1 - cos dE),      g = dt + (sin dE - dE) / n
        fdot = -sqrt(mu a) sin dE / (r r0),  gdot = 1 - a/r (1 - cos dE)
    """
    r0 = _vec3(r, "r")
    v0 = _vec3(v, "v")
    mu = _check_mu(mu)
    dt = float(dt)
    if not math.isfinite(dt):
        raise ValueError(f"dt = {dt!r} must be finite")
    a = osculating_sma(r0, v0, mu)
    r0m = math.sqrt(r0 @ r0)
    n = math.sqrt(mu / a ** 3)
    P = TWO_PI / n
    dt_red = dt - math.floor(dt / P) * P  # whole revolutions change nothing
    M = n * dt_red
    c0 = 1.0 - r0m / a  # e cos E0
    s0 = float(r0 @ v0) / math.sqrt(mu * a)  # e sin E0
    e = math.hypot(c0, s0)
    if e >= 1.0:
        raise ValueError(f"eccentricity e = {e!r} >= 1: only closed orbits are supported")
    # Kepler's equation for dE: M = dE - c0 sin dE + s0 (1 - cos dE), derivative 1 - e cos(E0 + dE)
    dE = M
    for _ in range(60):
        sd, cd = math.sin(dE), math.cos(dE)
        f_ = dE - c0 * sd + s0 * (1.0 - cd) - M
        fp = 1.0 - c0 * cd + s0 * sd
        step = -f_ / fp
        dE += step
        if abs(step) < 1e-15:
            break
    sd, cd = math.sin(dE), math.cos(dE)
    f = 1.0 - a / r0m * (1.0 - cd)
    g = dt_red + (sd - dE) / n
    rr = f * r0 + g * v0
    rm = math.sqrt(rr @ rr)
    fdot = -math.sqrt(mu * a) * sd / (rm * r0m)
    gdot = 1.0 - a / rm * (1.0 - cd)
    return rr, fdot * r0 + gdot * v0


# ---- J2 secular rates and the thesis' delta-v ------------------------------------------------
def j2_secular_rates(a, e, i, mu=MU_EARTH, j2=J2_EGM96, r_eq=R_EQ):
    """(dRAAN/dt, dargp/dt) in rad/s, first-order J2 secular rates (Vallado Eq. 9-41):

        dRAAN/dt = -3 n R^2 J2 cos i / (2 p^2),   dargp/dt = 3 n R^2 J2 (4 - 5 sin^2 i) / (4 p^2)

    with n = sqrt(mu / a^3) and p = a (1 - e^2)."""
    a, e = _check_a_e(a, e)
    return j2_secular_core(a, e, float(i), _check_mu(mu), float(j2), float(r_eq))


@njit(cache=True)
def j2_secular_core(a, e, i, mu, j2, r_eq):
    """j2_secular_rates without the checks, compiled (the orbit-averaged model's integration calls it)."""
    n = math.sqrt(mu / a ** 3.0)  # mean_motion
    p = a * (1.0 - e * e)
    k = n * r_eq * r_eq * j2 / (p * p)
    si = math.sin(i)
    return -1.5 * k * math.cos(i), 0.75 * k * (4.0 - 5.0 * si * si)


def initial_elements(p, mu=MU_EARTH):
    """(a, e, i, raan, argp, nu) of an orbit FMU's initial-state parameters `p` (a dict): the
    elements sma0 ... ta0, or with p["cartesian0"] the elements of the state r0_N, v0_N."""
    if not p.get("cartesian0"):
        return p["sma0"], p["ecc0"], p["inc0"], p["raan0"], p["argp0"], p["ta0"]
    r = [p[f"r0_N[{k}]"] for k in (1, 2, 3)]
    v = [p[f"v0_N[{k}]"] for k in (1, 2, 3)]
    try:
        return cartesian_to_kepler(r, v, mu)
    except ValueError as exc:
        raise ValueError(f"r0_N = {r} m, v0_N = {v} m/s: {exc}") from None
