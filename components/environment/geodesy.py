"""Earth-fixed coordinates and altitudes shared by the orbit and atmosphere models.

Frames: N is the product's inertial frame (docs/conventions.md), used as true-of-date; the Earth-fixed
frame E is N rotated about z by the Greenwich mean sidereal time (IAU 1982, as in
`components.environment.magnetic_field.gmst`), r_E = R3(GMST) r_N. Polar motion, precession and nutation
are ignored: over a mission they move a point by far less than the uncertainty of any density
model.

Altitudes, both in metres:
- geodetic altitude: height above the WGS-84 ellipsoid along the ellipsoid normal (what
  atmosphere models and the re-entry test use);
- spherical altitude: |r| minus the equatorial radius 6378.1363 km (what the thesis plots, as
  FreeFlyer's "A - Earth.Radius" for the semi-major axis).

WGS-84: a = 6378137 m, f = 1/298.257223563 (NIMA TR8350.2). Geodetic latitude from Earth-fixed
coordinates by Bowring's method with two refinements (error well below 1 mm in LEO).
"""
import math

from .magnetic_field import gmst
from ..core.constants import R_EQ, WGS84_A, WGS84_F
from ..core.time_utils import DAYS_PER_CENTURY, J2000_JD

WGS84_B = WGS84_A * (1.0 - WGS84_F)
WGS84_E2 = WGS84_F * (2.0 - WGS84_F)


def gmst_of_jd(jd_utc):
    """GMST (rad) at a UTC Julian date (UTC used for UT1)."""
    return gmst((jd_utc - J2000_JD) / DAYS_PER_CENTURY)


def inertial_to_earth_fixed(r_N, theta):
    """r_E = R3(theta) r_N for the sidereal angle theta (rad)."""
    c, s = math.cos(theta), math.sin(theta)
    x, y, z = r_N
    return (c * x + s * y, -s * x + c * y, z)


def earth_fixed_to_inertial(r_E, theta):
    c, s = math.cos(theta), math.sin(theta)
    x, y, z = r_E
    return (c * x - s * y, s * x + c * y, z)


def geodetic_from_earth_fixed(r_E):
    """(geodetic latitude rad, longitude rad in (-pi, pi], height above WGS-84 m)."""
    x, y, z = r_E
    p = math.hypot(x, y)
    lon = math.atan2(y, x)
    if p < 1e-9:  # on the polar axis
        lat = math.copysign(math.pi / 2.0, z)
        return lat, lon, abs(z) - WGS84_B
    ep2 = WGS84_E2 / (1.0 - WGS84_E2)
    beta = math.atan2(z * WGS84_A, p * WGS84_B)  # Bowring's first guess (reduced latitude)
    lat = 0.0
    for _ in range(3):
        sb, cb = math.sin(beta), math.cos(beta)
        lat = math.atan2(z + ep2 * WGS84_B * sb ** 3, p - WGS84_E2 * WGS84_A * cb ** 3)
        beta = math.atan2((1.0 - WGS84_F) * math.sin(lat), math.cos(lat))
    sl = math.sin(lat)
    n = WGS84_A / math.sqrt(1.0 - WGS84_E2 * sl * sl)
    if abs(lat) < math.radians(80.0):
        h = p / math.cos(lat) - n
    else:
        h = z / sl - n * (1.0 - WGS84_E2)
    return lat, lon, h


def geodetic_from_inertial(r_N, jd_utc):
    """(geodetic latitude rad, east longitude rad, geodetic altitude m) of an N position (m)."""
    return geodetic_from_earth_fixed(inertial_to_earth_fixed(r_N, gmst_of_jd(jd_utc)))


def spherical_altitude(r_N):
    """|r| - 6378.1363 km (m)."""
    x, y, z = r_N
    return math.sqrt(x * x + y * y + z * z) - R_EQ
