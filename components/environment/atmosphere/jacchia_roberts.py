"""Jacchia-Roberts atmosphere: Jacchia's 1970 model (J70) evaluated with Roberts' analytic
integration of the diffusion equation, as used by GMAT and FreeFlyer (thesis section 2.5).

References: L. G. Jacchia, "New static models of the thermosphere and exosphere with
empirical temperature profiles", SAO Special Report 313 (1970); C. E. Roberts, "An analytic
model for upper atmosphere densities based upon Jacchia's 1970 models", Celestial Mechanics 4
(1971) 368-377; Vallado, Fundamentals of Astrodynamics (3rd ed.) section 8.6.3; GMAT's
JacchiaRobertsAtmosphere and SolarFluxReader (NASA, Apache 2.0), whose constants and
conventions we follow so that our densities reproduce GMAT's test vectors. Our own code.

Steps (altitudes z in km above the ellipsoid, temperatures in K, densities in g/cm^3 inside):
1. Exospheric temperature: nighttime global minimum Tc = 379 + 3.24 F10.7a + 1.3 (F10.7 -
   F10.7a); diurnal variation T1 = Tc [1 + 0.3 (sin^2.2 theta + cos^3(tau/2)(cos^2.2 eta -
   sin^2.2 theta))] with theta = |phi + dec_sun|/2, eta = |phi - dec_sun|/2, tau = H - 37 deg +
   6 deg sin(H + 43 deg), H the Sun's hour angle; geomagnetic term T_inf = T1 + 28 Kp +
   0.03 e^Kp (z >= 200 km) or T1 + 14 Kp + 0.02 e^Kp (z < 200 km).
2. Inflection-point temperature Tx = 371.6678 + 0.0518806 T_inf - 294.3505 exp(-0.00216222
   T_inf); temperature profile: quartic polynomial below 125 km, Roberts' exponential above.
3. Density: 90-100 km and 100-125 km from Roberts' closed-form integrals (partial fractions
   over the real roots and the complex pair of the temperature polynomial), above 125 km the
   sum over N2, Ar, He, O2, O (and H above 500 km) of Roberts' closed form with the 125 km
   constituent densities from the T_inf polynomials; helium with the seasonal-latitudinal
   factor.
4. Corrections (log10 of density): geomagnetic (below 200 km) 0.012 Kp + 1.2e-5 e^Kp;
   semi-annual f(z) g(t); seasonal-latitudinal 0.014 (z - 90) eta exp(-0.0013 (z - 90)^2).

Out of range: below 90 km GMAT returns the 90 km density constant; we continue it down with
the 5.382 km scale height of the 90 km band of Vallado's table (so that the density keeps
increasing downwards). Above 2500 km the density is zero (as GMAT).

Space weather as GMAT's SolarFluxReader reads a CSSI file (historic/daily data): the day's
record is the one of the UTC date, or the previous date before 08:00 UTC (05:00 before
1991-05-31, when the F10.7 measurement time changed); F10.7 is the observed flux of the day
before that record, F10.7a the observed 81-day centred mean of the record; Kp the 3-hourly Kp
6.7 h before the epoch. After the file's last entry the last entry is held.

Geometry: geodetic latitude and altitude on WGS-84 (components.environment.geodesy; GMAT's Earth ellipsoid
differs by 0.3 m in radius); Roberts' Earth radius is GMAT's polar radius 6378.1363 (1 -
0.0033527) km. The Sun: low-precision formulae of components.environment.sun in the kernel.
"""
import math

import numpy as np

from ...core.jit import njit
from ...core.constants import R_EQ
from ...core.time_utils import DAYS_PER_CENTURY, J2000_JD
from .. import space_weather
from .base import DensityModel, geodetic_nb, gmst_rotation, rotated, sun_position_au_nb

RHO_ZERO = 3.46e-9   # g/cm^3 at 90 km
TZERO = 183.0        # K at 90 km
G_ZERO = 9.80665
GAS_CON = 8.31432
AVOGADRO = 6.022045e23
POLAR_RADIUS = R_EQ / 1e3 * (1.0 - 0.0033527)  # km, GMAT's Earth (its flattening 0.0033527)
SCALE_BELOW_90 = 5.382  # km, Vallado Table 8-4, 90 km band
JD_1958 = 2436204.5     # 1958-01-01 0h UTC, origin of Jacchia's semi-annual time
F107_REF_JD = 2448408.0  # GMAT's f107RefEpoch (A.1 MJD 18408): measurement time moved 17h -> 20h

CON_C = np.array([-89284375.0, 3542400.0, -52687.5, 340.5, -0.8])
CON_L = np.array([0.1031445e5, 0.2341230e1, 0.1579202e-2, -0.1252487e-5, 0.2462708e-9])
MZERO = 28.82678
M_CON = np.array([-435093.363387, 28275.5646391, -765.33466108, 11.043387545, -0.08958790995,
                  0.00038737586, -0.000000697444])
S_CON = np.array([3144902516.672729, -123774885.4832917, 1816141.096520398, -11403.31079489267,
                  24.36498612105595, 0.008957502869707995])
S_BETA = np.array([-52864482.17910969, -16632.50847336828, -1.308252378125, 0.0, 0.0, 0.0])
OMEGA = -0.94585589
ZETA_CON = np.array([0.1985549e-10, -0.1833490e-14, 0.1711735e-17, -0.1021474e-20, 0.3727894e-24,
                     -0.7734110e-28, 0.7026942e-32])
MOL_MASS = np.array([28.0134, 39.948, 4.0026, 31.9988, 15.9994, 1.00797])  # N2 Ar He O2 O H, g/mol
NUM_DENS = np.array([0.78110, 0.93432e-2, 0.61471e-5, 0.161778, 0.95544e-1])
CON_DEN = np.array([
    [0.1093155e2, 0.1186783e-2, -0.1677341e-5, 0.1420228e-8, -0.7139785e-12, 0.1969715e-15, -0.2296182e-19],
    [0.8049405e1, 0.2382822e-2, -0.3391366e-5, 0.2909714e-8, -0.1481702e-11, 0.4127600e-15, -0.4837461e-19],
    [0.7646886e1, -0.4383486e-3, 0.4694319e-6, -0.2894886e-9, 0.9451989e-13, -0.1270838e-16, 0.0],
    [0.9924237e1, 0.1600311e-2, -0.2274761e-5, 0.1938454e-8, -0.9782183e-12, 0.2698450e-15, -0.3131808e-19],
    [0.1097083e2, 0.6118742e-4, -0.1165003e-6, 0.9239354e-10, -0.3490739e-13, 0.5116298e-17, 0.0],
])


@njit(cache=True)
def _horner(c, n, x):
    s = c[n - 1]
    for i in range(n - 2, -1, -1):
        s = s * x + c[i]
    return s


@njit(cache=True)
def _real_root(c, n, x):
    """Newton's method for a real root of sum c[i] x^i (n coefficients) from x."""
    for _ in range(100):
        p = c[n - 1]
        dp = 0.0
        for i in range(n - 2, -1, -1):
            dp = dp * x + p
            p = p * x + c[i]
        dx = p / dp
        x -= dx
        if abs(dx) <= 1e-14 * abs(x):
            break
    return x


@njit(cache=True)
def _deflate(c, n, root):
    """Divide sum c[i] x^i (n coefficients) by (x - root) in place (n - 1 coefficients left)."""
    s = c[n - 1]
    for i in range(n - 2, -1, -1):
        save = c[i]
        c[i] = s
        s = save + s * root


@njit(cache=True)
def _temperature_roots(tx):
    """Roots of Roberts' quartic below 125 km: two real (near 125 and 200 km) and x +- i y."""
    c = np.empty(5)
    c[0] = CON_C[0] + 1500625.0 * tx / (tx - TZERO)
    for i in range(1, 5):
        c[i] = CON_C[i]
    r1 = _real_root(c, 5, 125.0)
    _deflate(c, 5, r1)
    r2 = _real_root(c, 4, 200.0)
    _deflate(c, 4, r2)
    # remaining quadratic c0 + c1 x + c2 x^2 with a complex pair x +- i y
    x = -c[1] / (2.0 * c[2])
    disc = c[0] / c[2] - x * x
    y = math.sqrt(disc) if disc > 0.0 else 0.0
    return r1, r2, x, y


@njit(cache=True)
def _partial_fractions(r1, r2, xr, yr, rp):
    rp2 = rp * rp
    roots_2 = xr * xr + yr * yr
    x_star = -2.0 * r1 * r2 * rp * (rp2 + 2.0 * rp * xr + roots_2)
    v = (rp + r1) * (rp + r2) * (rp2 + 2.0 * rp * xr + roots_2)
    u0 = (r1 - r2) * (r1 + rp) * (r1 + rp) * (r1 * r1 - 2.0 * r1 * xr + roots_2)
    u1 = (r1 - r2) * (r2 + rp) * (r2 + rp) * (r2 * r2 - 2.0 * r2 * xr + roots_2)
    w0 = r1 * r2 * rp * (rp + r1) * (rp + roots_2 / r1)
    w1 = r1 * r2 * rp * (rp + r2) * (rp + roots_2 / r2)
    return roots_2, x_star, v, u0, u1, w0, w1


@njit(cache=True)
def _rho_100(z, temperature, tx, r1, r2, xr, yr):
    """90-100 km (g/cm^3)."""
    rp = POLAR_RADIUS
    rp2 = rp * rp
    m_poly = _horner(M_CON, 7, z)
    b = np.empty(6)
    for i in range(6):
        b[i] = S_CON[i] + S_BETA[i] * tx / (tx - TZERO)
    roots_2, x_star, v, u0, u1, w0, w1 = _partial_fractions(r1, r2, xr, yr, rp)
    p2 = _horner(b, 6, r1) / u0
    p3 = -_horner(b, 6, r2) / u1
    p5 = _horner(b, 6, -rp) / v
    p4 = (b[0] - r1 * r2 * rp2 * (b[4] + b[5] * (2.0 * xr + r1 + r2 - rp)) + w0 * p2 + w1 * p3
          - r1 * r2 * b[5] * rp * roots_2 + r1 * r2 * (rp2 - roots_2) * p5) / x_star
    p1 = b[5] - 2.0 * p4 - p3 - p2
    p6 = (b[4] + b[5] * (2.0 * xr + r1 + r2 - rp) - p5 - 2.0 * (xr + rp) * p4 - (r2 + rp) * p3
          - (r1 + rp) * p2)
    log_f1 = (p1 * math.log((z + rp) / (90.0 + rp)) + p2 * math.log((z - r1) / (90.0 - r1))
              + p3 * math.log((z - r2) / (90.0 - r2))
              + p4 * math.log((z * z - 2.0 * xr * z + roots_2) / (8100.0 - 180.0 * xr + roots_2)))
    f2 = ((z - 90.0) * (M_CON[6] + p5 / ((z + rp) * (90.0 + rp)))
          + p6 * math.atan(yr * (z - 90.0) / (yr * yr + (z - xr) * (90.0 - xr))) / yr)
    factor_k = -G_ZERO / (GAS_CON * (tx - TZERO))
    return RHO_ZERO * TZERO * m_poly * math.exp(factor_k * (log_f1 + f2)) / (MZERO * temperature)


@njit(cache=True)
def _rho_125(z, temperature, tx, t_inf, r1, r2, xr, yr):
    """100-125 km (g/cm^3)."""
    rp = POLAR_RADIUS
    rp2 = rp * rp
    rho_prime = _horner(ZETA_CON, 7, t_inf)
    t_100 = tx + OMEGA * (tx - TZERO)
    roots_2, x_star, v, u0, u1, w0, w1 = _partial_fractions(r1, r2, xr, yr, rp)
    q2 = 1.0 / u0
    q3 = -1.0 / u1
    q5 = 1.0 / v
    q4 = (1.0 + w0 * q2 + w1 * q3 + r1 * r2 * (rp2 - roots_2) * q5) / x_star
    q1 = -2.0 * q4 - q3 - q2
    q6 = -q5 - 2.0 * (xr + rp) * q4 - (r2 + rp) * q3 - (r1 + rp) * q2
    log_f3 = (q1 * math.log((z + rp) / (100.0 + rp)) + q2 * math.log((z - r1) / (100.0 - r1))
              + q3 * math.log((z - r2) / (100.0 - r2))
              + q4 * math.log((z * z - 2.0 * xr * z + roots_2) / (1.0e4 - 200.0 * xr + roots_2)))
    f4 = ((z - 100.0) * q5 / ((z + rp) * (100.0 + rp))
          + q6 * math.atan(yr * (z - 100.0) / (yr * yr + (z - xr) * (100.0 - xr))) / yr)
    factor_k = -1500625.0 * G_ZERO * rp2 / (GAS_CON * CON_C[4] * (tx - TZERO))
    rho_sum = 0.0
    for i in range(5):
        rhoi = MOL_MASS[i] * NUM_DENS[i] * math.exp(MOL_MASS[i] * factor_k * (f4 + log_f3))
        if i == 2:
            rhoi *= (t_100 / temperature) ** -0.38
        rho_sum += rhoi
    return rho_sum * rho_prime * t_100 / temperature


@njit(cache=True)
def _rho_high(z, temperature, tx, t_inf, sum_l, t_500, sun_dec, lat):
    """125-2500 km (g/cm^3)."""
    rp = POLAR_RADIUS
    rho = 0.0
    for i in range(6):
        gamma = (35.0 * MOL_MASS[i] * G_ZERO * rp * rp * (t_inf - tx)
                 / (GAS_CON * sum_l * t_inf * (tx - TZERO) * (rp + 125.0)))
        exp1 = 1.0 + gamma
        if i == 5:
            if z > 500.0:
                rho += (MOL_MASS[5] * 10.0 ** (73.13 - (39.4 - 5.5 * math.log10(t_500)) * math.log10(t_500))
                        * (t_500 / temperature) ** exp1 * ((t_inf - temperature) / (t_inf - t_500)) ** gamma
                        / AVOGADRO)
            continue
        di = 10.0 ** _horner(CON_DEN[i], 7, t_inf) / AVOGADRO
        f = 1.0
        if i == 2:  # helium: seasonal-latitudinal variation
            exp1 -= 0.38
            sgn = 1.0 if sun_dec >= 0.0 else -1.0
            f = 10.0 ** (4.9914 * abs(sun_dec) * (math.sin(0.25 * math.pi - 0.5 * lat * sgn) ** 3 - 0.35355)
                         / math.pi)
        rho += f * MOL_MASS[i] * di * (tx / temperature) ** exp1 * ((t_inf - temperature) / (t_inf - tx)) ** gamma
    return rho


@njit(cache=True)
def _temperatures(z, t1, kp, exp_kp):
    """(T_inf, Tx, T(z), L polynomial) at altitude z for the diurnal temperature t1; exp_kp = e^Kp."""
    if z < 200.0:
        t_inf = t1 + 14.0 * kp + 0.02 * exp_kp
    else:
        t_inf = t1 + 28.0 * kp + 0.03 * exp_kp
    tx = 371.6678 + 0.0518806 * t_inf - 294.3505 * math.exp(-0.00216222 * t_inf)
    sum_l = _horner(CON_L, 5, t_inf)
    if z < 125.0:
        temperature = tx + (tx - TZERO) * _horner(CON_C, 5, z) / 1.500625e6
    elif z > 125.0:
        temperature = t_inf - (t_inf - tx) * math.exp(-(tx - TZERO) / (t_inf - tx) * (z - 125.0) / 35.0
                                                      * sum_l / (POLAR_RADIUS + z))
    else:
        temperature = tx
    return t_inf, tx, temperature, sum_l


@njit(cache=True)
def jr_time_terms(f107, f107a, kp, jd_utc):
    """The terms of jr_density that depend on the time alone: (nighttime minimum exospheric
    temperature Tc, e^Kp, the semi-annual g(t), the sine of the seasonal-latitudinal variation),
    the same at every position of one time."""
    tc = 379.0 + 3.24 * f107a + 1.3 * (f107 - f107a)
    day_58 = (jd_utc - JD_1958) / 365.2422
    tausa = day_58 + 0.09544 * ((0.5 * (1.0 + math.sin(2.0 * math.pi * day_58 + 6.035))) ** 1.65 - 0.5)
    alpha = math.sin(4.0 * math.pi * tausa + 4.259)
    g = 0.02835 + (0.3817 + 0.17829 * math.sin(2.0 * math.pi * tausa + 4.137)) * alpha
    return tc, math.exp(kp), g, math.sin(2.0 * math.pi * day_58 + 1.72)


@njit(cache=True)
def jr_density(z, lat, hour_angle, sun_dec, f107, f107a, kp, jd_utc):
    """Jacchia-Roberts density in kg/m^3 at geodetic altitude z (km) and latitude lat (rad),
    Sun hour angle (rad, position's right ascension minus the Sun's) and declination (rad),
    F10.7 (previous day), 81-day mean F10.7, 3-hourly Kp (6.7 h before), UTC Julian date."""
    tc, exp_kp, g, season = jr_time_terms(f107, f107a, kp, jd_utc)
    return jr_density_at(z, lat, hour_angle, sun_dec, kp, tc, exp_kp, g, season)


@njit(cache=True)
def jr_density_at(z, lat, hour_angle, sun_dec, kp, tc, exp_kp, g, season):
    """jr_density with the terms of the time from jr_time_terms."""
    if z > 2500.0:
        return 0.0
    below = 0.0
    if z < 90.0:
        below = 90.0 - z
        z = 90.0
    # exospheric temperature
    theta = 0.5 * abs(lat + sun_dec)
    eta = 0.5 * abs(lat - sun_dec)
    tau = hour_angle - 0.64577182325 + 0.10471975512 * math.sin(hour_angle + 0.75049157836)
    if tau < -math.pi:
        tau += 2.0 * math.pi
    elif tau > math.pi:
        tau -= 2.0 * math.pi
    th22 = math.sin(theta) ** 2.2
    t1 = tc * (1.0 + 0.3 * (th22 + math.cos(0.5 * tau) ** 3 * (math.cos(eta) ** 2.2 - th22)))
    t_inf, tx, temperature, sum_l = _temperatures(z, t1, kp, exp_kp)
    if z <= 90.0:
        rho = RHO_ZERO
    elif z <= 125.0:
        r1, r2, xr, yr = _temperature_roots(tx)
        if z < 100.0:
            rho = _rho_100(z, temperature, tx, r1, r2, xr, yr)
        else:
            rho = _rho_125(z, temperature, tx, t_inf, r1, r2, xr, yr)
    else:
        t_500 = _temperatures(500.0, t1, kp, exp_kp)[2]
        rho = _rho_high(z, temperature, tx, t_inf, sum_l, t_500, sun_dec, lat)
    # corrections: geomagnetic (below 200 km), semi-annual, seasonal-latitudinal
    geo_cor = 0.012 * kp + 0.000012 * exp_kp if z < 200.0 else 0.0
    f = (5.876e-7 * z ** 2.331 + 0.06328) * math.exp(-0.002868 * z)
    sl = math.sin(lat)
    eta_lat = season * sl * abs(sl)
    slat_cor = 0.014 * (z - 90.0) * eta_lat * math.exp(-0.0013 * (z - 90.0) * (z - 90.0))
    rho *= 10.0 ** (geo_cor + f * g + slat_cor)
    if below > 0.0:
        rho *= math.exp(below / SCALE_BELOW_90)
    return rho * 1.0e3  # g/cm^3 -> kg/m^3


@njit(cache=True)
def jr_indices(jd, jd0, daily, f107_prev_col, f107a_col, kp_col):
    """(F10.7, F10.7a, Kp) for Jacchia-Roberts at UTC Julian date jd, GMAT's selection (module
    docstring). Raises before the first day of the table. `f107_prev_col` is a previous-day
    column of components.environment.space_weather (the same day's flux is the column before it)."""
    n = daily.shape[0]
    d = space_weather.day_index(jd, jd0, n)
    if d < 0:
        raise ValueError("date before the first entry of the space-weather data")
    frac = jd - jd0 - math.floor(jd - jd0)
    offset = 5.0 / 24.0 if jd < F107_REF_JD else 8.0 / 24.0
    fd = d
    if jd - jd0 >= n:  # after the last entry: the last entry is held, also as "the previous day"
        f107 = daily[n - 1, f107_prev_col - 1]
    else:
        if frac < offset:
            fd = d - 1 if d > 0 else 0
        f107 = daily[fd, f107_prev_col]
    f107a = daily[fd, f107a_col]
    k = math.floor((jd - jd0) * 8.0 - 6.7 / 3.0)
    if k < 0.0:
        k = 0.0
    if k > 8 * n - 1:
        k = 8.0 * n - 1.0
    ki = int(k)
    kp = daily[ki // 8, kp_col + ki % 8]
    return f107, f107a, kp


# the slots of the kernel's memo (the last of its data): the UTC Julian date the others are of, the
# GMST rotation, the Sun's x and y (AU) and declination, Kp and jr_time_terms
_AT_JD, _COS_GMST, _SIN_GMST, _SUN_X, _SUN_Y, _SUN_DEC, _KP, _TC, _EXP_KP, _G, _SEASON = range(11)


@njit(cache=True)
def jacchia_roberts_kernel(r, jd, data):
    """The density (kg/m^3) at the N position r (m) at the UTC Julian date jd. What depends on the
    time alone (the indices, GMST, the Sun, jr_time_terms) is kept in the memo for the next call
    at the same time: the orbit-averaged model's quadrature asks for 16 positions at one time,
    and computes them once instead of 16 times (a fifth of the kernel's cost; the same bits)."""
    jd0, daily, f107_prev_col, f107a_col, kp_col, memo = data
    if memo[_AT_JD] != jd:
        f107, f107a, kp = jr_indices(jd, jd0, daily, f107_prev_col, f107a_col, kp_col)
        memo[_AT_JD] = math.nan  # the slots are of no time while they change
        memo[_COS_GMST], memo[_SIN_GMST] = gmst_rotation(jd)
        s = sun_position_au_nb((jd - J2000_JD) / DAYS_PER_CENTURY)
        memo[_SUN_X], memo[_SUN_Y] = s[0], s[1]
        memo[_SUN_DEC] = math.atan2(s[2], math.sqrt(s[0] * s[0] + s[1] * s[1]))
        memo[_KP] = kp
        memo[_TC], memo[_EXP_KP], memo[_G], memo[_SEASON] = jr_time_terms(f107, f107a, kp, jd)
        memo[_AT_JD] = jd
    lat, lon, h = geodetic_nb(rotated(r, memo[_COS_GMST], memo[_SIN_GMST]))
    sx, sy = memo[_SUN_X], memo[_SUN_Y]
    hour_angle = math.atan2(sx * r[1] - sy * r[0], sx * r[0] + sy * r[1])
    return jr_density_at(h / 1e3, lat, hour_angle, memo[_SUN_DEC], memo[_KP], memo[_TC], memo[_EXP_KP], memo[_G],
                         memo[_SEASON])


class JacchiaRobertsModel(DensityModel):
    """Jacchia-Roberts with indices from a components.environment.space_weather source (observed F10.7,
    as GMAT; `kind="adjusted"` uses the 1 AU-adjusted flux instead)."""

    name = "jacchia_roberts"

    def __init__(self, space_weather_source, kind="observed"):
        cols = {"observed": (space_weather.COL_F107_OBS_PREV, space_weather.COL_F107_OBS_CTR81),
                "adjusted": (space_weather.COL_F107_ADJ_PREV, space_weather.COL_F107_ADJ_CTR81)}
        if kind not in cols:
            raise ValueError(f"F10.7 kind {kind!r} must be one of {tuple(cols)}")
        self.space_weather = space_weather_source
        jd0, daily, _ = space_weather_source.kernel_arrays()
        self.kernel = jacchia_roberts_kernel
        # the memo makes a model one caller's at a time (as an FMU instance is): two threads sharing one
        # in plain Python could read each other's half-written terms
        self.kernel_data = (float(jd0), np.ascontiguousarray(daily, dtype=np.float64), cols[kind][0], cols[kind][1],
                            space_weather.COL_KP, np.full(11, math.nan))

    def indices(self, jd_utc):
        """(F10.7 sfu, 81-day mean F10.7 sfu, Kp) used at jd_utc."""
        jd0, daily, c1, c2, c3, _ = self.kernel_data
        self.space_weather._row(jd_utc)  # ValueError naming the date and the coverage
        return tuple(float(v) for v in jr_indices(float(jd_utc), jd0, daily, c1, c2, c3))

    def density(self, r_N, jd_utc):
        self.space_weather._row(jd_utc)  # the Python side raises a clear error before the first day
        return super().density(r_N, jd_utc)
