"""Physical constants: each defined once, here, for every model, FMU wrapper, system generator
and application of the product.

Two Earth models appear, each where its source uses it:
- the thesis' gravity field (FreeFlyer / EGM96): `MU_EARTH`, `R_EQ`. Orbits, drag, the de-orbit
  sizing and the altitudes the thesis plots (|r| - R_EQ) use these;
- WGS-84: `WGS84_A`, `WGS84_F` (geodetic latitude and altitude, ground stations),
  `MU_EARTH_WGS84` (the analytic circular orbit) and `OMEGA_EARTH_WGS84` (the rotation of the
  atmosphere in the Cowell propagator's drag).
Time: SI seconds; a day is 86400 s and a year is the Julian year of 365.25 days.
"""
import math

MU_EARTH = 398600.4415e9  # m^3/s^2, EGM96 (thesis Eq. 2, FreeFlyer Earth.Mu)
R_EQ = 6378136.3  # m, EGM96 equatorial radius (the thesis' 6378.1363 km)

WGS84_A = 6378137.0  # m, WGS-84 semi-major axis (NIMA TR8350.2)
WGS84_F = 1.0 / 298.257223563  # WGS-84 flattening
MU_EARTH_WGS84 = 3.986004418e14  # m^3/s^2, WGS-84 (atmosphere included)
OMEGA_EARTH_WGS84 = 7.292115e-5  # rad/s, WGS-84 nominal Earth rotation rate
OMEGA_EARTH = 7.292115146706979e-5  # rad/s, Earth rotation rate (IERS conventions, as GMAT)

ASTRONOMICAL_UNIT = 149597870700.0  # m (IAU 2012 Resolution B2, exact)
SOLAR_FLUX_1AU = 1361.0  # W/m2, total solar irradiance at 1 AU (IAU 2015 Resolution B3 nominal)

DAY = 86400.0  # s
DAYS_PER_JULIAN_YEAR = 365.25
YEAR = DAYS_PER_JULIAN_YEAR * DAY  # s, Julian year
DAYS_PER_CENTURY = 36525.0  # Julian century

DEG = math.pi / 180.0  # rad per degree
