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

Left out: the tesseral and sectoral terms (m > 0) that the thesis' FreeFlyer runs also had on.
Their effect on a LEO orbit is short-periodic (metres to tens of metres in position, no secular
change of a), far below the drag-model uncertainty of a lifetime prediction; adding them needs
the Earth-fixed rotation inside the force model and was not done in the time available.
"""
import math

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
