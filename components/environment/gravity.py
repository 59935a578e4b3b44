"""Earth gravity: point mass plus the zonal harmonics J2..J6 of EGM96 (accelerations in N, m/s^2).

Potential (zonal part of the spherical-harmonic expansion, Vallado Eq. 8-19):

    U = mu/r [1 - sum_{n=2..nmax} J_n (R/r)^n P_n(s)],   s = z/r = sin(geocentric latitude)

and its gradient, with P_n' = dP_n/ds,

    a = -mu r/r^3 + sum_n mu J_n R^n / r^(n+2) [((n+1) P_n + s P_n') r/r - P_n' z_hat]

(for n = 2 this is the familiar -3/2 J2 mu R^2/r^5 [x (1 - 5 s^2), y (1 - 5 s^2), z (3 - 5 s^2)]).
P_n and P_n' by Bonnet's recursion n P_n = (2n-1) s P_{n-1} - (n-1) P_{n-2} and
P_n' = s P_{n-1}' + n P_{n-1}.

Zonal terms depend only on z and |r|, and z is the same axis in N and in the Earth-fixed frame
(no polar motion or precession, components/environment/geodesy.py), so they are evaluated in N directly.

Coefficients: unnormalized J_n = -sqrt(2n+1) C_n0bar from the fully normalized EGM96 values
(Lemoine et al. 1998, NASA/TP-1998-206861, file egm96_to360.ascii):

    C20bar = -0.484165371736e-03   C30bar = 0.957254173792e-06   C40bar = 0.539873863789e-06
    C50bar =  0.685323475630e-07   C60bar = -0.149957994714e-06

with mu = 398600.4415 km^3/s^2 and R = 6378.1363 km (EGM96, the thesis' values).

The tesseral and sectoral terms (m > 0) that the thesis' FreeFlyer runs also had on are in
`accel_harmonics` below (the GGM03S field to degree and order 36 in the Earth-fixed frame, the
Orbit FMU's gravity_degree); this zonal kernel stays the default, the thesis' model. Their effect
on a LEO orbit is short-periodic (metres to a kilometre in position after a day, no secular change
of a), far below the drag-model uncertainty of a lifetime prediction.
"""
import math
import os

import numpy as np

from ..core.jit import njit
from ..core.constants import MU_EARTH, R_EQ

EGM96_CBAR_N0 = {2: -0.484165371736e-03, 3: 0.957254173792e-06, 4: 0.539873863789e-06,
                 5: 0.685323475630e-07, 6: -0.149957994714e-06}
MAX_ZONAL_DEGREE = 6


def zonal_coefficients(degree=MAX_ZONAL_DEGREE):
    """float64 array J with J[n] = J_n for 2 <= n <= degree (J[0] = J[1] = 0); degree 0 or 1 means
    point mass only."""
    degree = int(degree)
    if not 0 <= degree <= MAX_ZONAL_DEGREE:
        raise ValueError(f"zonal_degree = {degree!r} must be an integer in [0, {MAX_ZONAL_DEGREE}] "
                         "(0: point mass only, 2: J2, ..., 6: J2..J6)")
    J = np.zeros(MAX_ZONAL_DEGREE + 1)
    for n in range(2, degree + 1):
        J[n] = -math.sqrt(2.0 * n + 1.0) * EGM96_CBAR_N0[n]
    return J


@njit(cache=True, fastmath=False)
def accel_zonal(x, y, z, mu, r_eq, J, nmax):
    """(ax, ay, az) in m/s^2: point mass + zonal terms J[2..nmax] at position (x, y, z) in N (m)."""
    r2 = x * x + y * y + z * z
    r = math.sqrt(r2)
    inv_r = 1.0 / r
    k0 = -mu * inv_r * inv_r * inv_r
    ax = k0 * x
    ay = k0 * y
    az = k0 * z
    if nmax >= 2:
        s = z * inv_r
        # Legendre recursion
        p_nm2 = 1.0   # P_0
        p_nm1 = s     # P_1
        dp_nm1 = 1.0  # P_1'
        rr = r_eq * inv_r  # R/r
        rrn = rr          # (R/r)^n, updated inside
        radial = 0.0
        axial = 0.0
        for n in range(2, nmax + 1):
            p_n = ((2.0 * n - 1.0) * s * p_nm1 - (n - 1.0) * p_nm2) / n
            dp_n = s * dp_nm1 + n * p_nm1
            rrn = rrn * rr
            jn = J[n]
            if jn != 0.0:
                c = jn * rrn
                radial += c * ((n + 1.0) * p_n + s * dp_n)
                axial += c * dp_n
            p_nm2 = p_nm1
            p_nm1 = p_n
            dp_nm1 = dp_n
        k = mu * inv_r * inv_r  # mu/r^2 ; times (R/r)^n already in c
        ax += k * radial * x * inv_r
        ay += k * radial * y * inv_r
        az += k * (radial * z * inv_r - axial)
    return ax, ay, az


@njit(cache=True)
def potential_zonal(x, y, z, mu, r_eq, J, nmax):
    """U (m^2/s^2, positive convention a = grad U) for tests of accel_zonal."""
    r = math.sqrt(x * x + y * y + z * z)
    s = z / r
    u = 1.0
    p_nm2 = 1.0
    p_nm1 = s
    for n in range(2, nmax + 1):
        p_n = ((2.0 * n - 1.0) * s * p_nm1 - (n - 1.0) * p_nm2) / n
        u -= J[n] * (r_eq / r) ** n * p_n
        p_nm2 = p_nm1
        p_nm1 = p_n
    return mu / r * u


def acceleration(r_N, degree=MAX_ZONAL_DEGREE, mu=MU_EARTH, r_eq=R_EQ):
    """Gravity acceleration (numpy array, m/s^2) at r_N (m): point mass + J2..J`degree`."""
    r = np.asarray(r_N, dtype=float)
    if r.shape != (3,) or not np.all(np.isfinite(r)) or not np.any(r):
        raise ValueError(f"r_N = {r_N!r} must be 3 finite numbers, not all zero")
    J = zonal_coefficients(degree)
    return np.array(accel_zonal(r[0], r[1], r[2], float(mu), float(r_eq), J, int(degree)))


# ---- spherical harmonics to any degree and order, and the Sun and Moon as point masses -------
# Coefficients: GGM03S (Tapley et al. 2007, "The GGM03 Mean Earth Gravity Model from GRACE", CSR,
# University of Texas at Austin; fully normalized C_nm, S_nm), truncated to degree and order 36
# from the copy in Basilisk's repository (supportData/LocalGravData/GGM03S.txt, ISC licence), in
# its format: a header "R, mu, omega, max degree, max order, normalized, ...", then rows
# "n, m, C, S, sigma C, sigma S". Same mu and R as EGM96 (398600.4415 km3/s2, 6378.1363 km).
PACKAGE_DATA = ("data/GGM03S_degree36.txt",)  # what an FMU that imports this bundles
GGM03S_FILE = os.path.join(os.path.dirname(__file__), "data", "GGM03S_degree36.txt")
MU_SUN = 1.32712440018e20  # m^3/s^2 (DE405, as Montenbruck and Gill Table 3.4)
MU_MOON = 4.9028e12  # m^3/s^2 (Montenbruck and Gill Table 3.4)
_GRAVITY_FIELDS = {}


def read_gravity_field(path=GGM03S_FILE):
    """(R, mu, Cbar, Sbar) of a coefficient file in the format above: fully normalized arrays
    [n, m] up to the file's degree. ValueError naming the file and line for a malformed one."""
    with open(path) as f:
        lines = f.read().splitlines()
    try:
        header = [float(x) for x in lines[0].split(",")[:6]]
    except (ValueError, IndexError):
        raise ValueError(f"{path}:1: expected 'R, mu, omega, degree, order, normalized, ...'") from None
    r_ref, mu, degree = header[0], header[1], int(header[3])
    if header[5] != 1.0:
        raise ValueError(f"{path}:1: only fully normalized coefficients (flag 1) are read")
    C = np.zeros((degree + 1, degree + 1))
    S = np.zeros_like(C)
    for number, line in enumerate(lines[1:], 2):
        if not line.strip():
            continue
        try:
            fields = line.split(",")
            n, m, c, s = int(fields[0]), int(fields[1]), float(fields[2]), float(fields[3])
        except (ValueError, IndexError):
            raise ValueError(f"{path}:{number}: expected 'n, m, C, S, ...'") from None
        if n > degree:
            break
        if not 0 <= m <= n:
            raise ValueError(f"{path}:{number}: order {m} outside 0..{n}")
        C[n, m], S[n, m] = c, s
    return r_ref, mu, C, S


def spherical_harmonic_coefficients(degree, order, path=GGM03S_FILE):
    """Unnormalized (C, S) arrays [n, m] of the file's model for 2 <= n <= degree, m <= order
    (the point mass and degree 1 zeroed: the zonal kernel's point mass supplies n = 0)."""
    if path not in _GRAVITY_FIELDS:
        _GRAVITY_FIELDS[path] = read_gravity_field(path)
    _, _, Cbar, Sbar = _GRAVITY_FIELDS[path]
    top = Cbar.shape[0] - 1
    if isinstance(degree, bool) or int(degree) != degree or not 2 <= int(degree) <= top:
        raise ValueError(f"gravity_degree = {degree!r} must be an integer in [2, {top}] (the coefficient file's "
                         "degree), or 0 for the zonal model")
    if isinstance(order, bool) or int(order) != order or not 0 <= int(order) <= int(degree):
        raise ValueError(f"gravity_order = {order!r} must be an integer in [0, gravity_degree = {degree}]")
    degree, order = int(degree), int(order)
    C = np.zeros((degree + 2, degree + 2))
    S = np.zeros_like(C)
    for n in range(2, degree + 1):
        for m in range(0, min(n, order) + 1):
            # N_nm = sqrt((2 - delta_m0) (2n + 1) (n - m)! / (n + m)!), unnormalized = N_nm * normalized
            k = math.sqrt((1.0 if m == 0 else 2.0) * (2 * n + 1) * math.exp(math.lgamma(n - m + 1)
                                                                           - math.lgamma(n + m + 1)))
            C[n, m], S[n, m] = k * Cbar[n, m], k * Sbar[n, m]
    return C, S


@njit(cache=True)
def accel_harmonics(x, y, z, mu, r_eq, C, S, nmax):
    """Acceleration (m/s^2, Earth-fixed frame) of the unnormalized terms C[n, m], S[n, m] for
    2 <= n <= nmax at the Earth-fixed position (m), by the V/W recursion of Montenbruck and Gill,
    Satellite Orbits, Eq. 3.29-3.33 (C[0, 0] and degree 1 not included)."""
    r2 = x * x + y * y + z * z
    rho = r_eq * r_eq / r2
    x0, y0, z0 = r_eq * x / r2, r_eq * y / r2, r_eq * z / r2
    top = nmax + 2
    V = np.zeros((top, top))
    W = np.zeros((top, top))
    V[0, 0] = r_eq / math.sqrt(r2)
    V[1, 0] = z0 * V[0, 0]
    for n in range(2, top):
        V[n, 0] = ((2 * n - 1) * z0 * V[n - 1, 0] - (n - 1) * rho * V[n - 2, 0]) / n
    for m in range(1, top):
        V[m, m] = (2 * m - 1) * (x0 * V[m - 1, m - 1] - y0 * W[m - 1, m - 1])
        W[m, m] = (2 * m - 1) * (x0 * W[m - 1, m - 1] + y0 * V[m - 1, m - 1])
        if m + 1 < top:
            V[m + 1, m] = (2 * m + 1) * z0 * V[m, m]
            W[m + 1, m] = (2 * m + 1) * z0 * W[m, m]
        for n in range(m + 2, top):
            V[n, m] = ((2 * n - 1) * z0 * V[n - 1, m] - (n + m - 1) * rho * V[n - 2, m]) / (n - m)
            W[n, m] = ((2 * n - 1) * z0 * W[n - 1, m] - (n + m - 1) * rho * W[n - 2, m]) / (n - m)
    ax = ay = az = 0.0
    for n in range(2, nmax + 1):
        for m in range(n + 1):
            c, s = C[n, m], S[n, m]
            if c == 0.0 and s == 0.0:
                continue
            if m == 0:
                ax -= c * V[n + 1, 1]
                ay -= c * W[n + 1, 1]
                az += (n + 1) * (-c * V[n + 1, 0])
            else:
                f = (n - m + 2) * (n - m + 1)
                ax += 0.5 * ((-c * V[n + 1, m + 1] - s * W[n + 1, m + 1])
                             + f * (c * V[n + 1, m - 1] + s * W[n + 1, m - 1]))
                ay += 0.5 * ((-c * W[n + 1, m + 1] + s * V[n + 1, m + 1])
                             + f * (-c * W[n + 1, m - 1] + s * V[n + 1, m - 1]))
                az += (n - m + 1) * (-c * V[n + 1, m] - s * W[n + 1, m])
    k = mu / (r_eq * r_eq)
    return k * ax, k * ay, k * az


@njit(cache=True)
def third_body(x, y, z, sx, sy, sz, mu_b):
    """Acceleration (m/s^2) of a point mass mu_b at s relative to the Earth on a spacecraft at r,
    relative to the Earth's centre (the indirect term included): mu_b [(s - r)/|s - r|^3 - s/|s|^3]."""
    dx, dy, dz = sx - x, sy - y, sz - z
    d3 = (dx * dx + dy * dy + dz * dz) ** 1.5
    s3 = (sx * sx + sy * sy + sz * sz) ** 1.5
    return (mu_b * (dx / d3 - sx / s3), mu_b * (dy / d3 - sy / s3), mu_b * (dz / d3 - sz / s3))


def acceleration_harmonics(r_ecef, degree, order=None, path=GGM03S_FILE):
    """The GGM03S terms 2 <= n <= degree, m <= order (default: degree) at the Earth-fixed position,
    without the point mass (numpy array, m/s^2)."""
    C, S = spherical_harmonic_coefficients(degree, degree if order is None else order, path)
    r_ref, mu, _, _ = _GRAVITY_FIELDS[path]
    r = np.asarray(r_ecef, dtype=float)
    return np.array(accel_harmonics(r[0], r[1], r[2], mu, r_ref, C, S, int(degree)))
