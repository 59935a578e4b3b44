"""Earth shadow: the conical umbra/penumbra model of Montenbruck and Gill, Satellite Orbits,
section 3.4.2 (also Vallado's SHADOW with the fractional overlap of the disks).

Seen from the spacecraft at r (= r_BN_N, Earth's centre at the origin) with the Sun at r_sun
(= r_SN_N), the Sun and Earth are disks of apparent radii a and b, their centres c apart:

    a = asin(R_sun / |r_sun - r|),  b = asin(R_earth / |r|),
    c = acos(-r . (r_sun - r) / (|r| |r_sun - r|))

    c >= a + b          no occultation                  sunlit fraction nu = 1
    c <= b - a          total occultation (umbra)       nu = 0
    c <= a - b          annular (Earth's disk inside the Sun's, spacecraft beyond the umbra
                        cone's apex, about 1.4 million km away)   nu = 1 - b^2 / a^2
    otherwise           partial (penumbra)              nu = 1 - A / (pi a^2) with the overlap
                        x = (c^2 + a^2 - b^2) / (2c), y = sqrt(a^2 - x^2),
                        A = a^2 acos(x / a) + b^2 acos((c - x) / b) - c y

The disks are uniform (no limb darkening), flat in the small-angle sense, and Earth is a
sphere of radius R_earth with no atmosphere (M&G's simplifications).
"""
import math

from ..core.constants import WGS84_A

SUN_RADIUS = 696.0e6  # m
DAY_THRESHOLD = 0.5


def _positive(name, value):
    value = float(value)
    if not (math.isfinite(value) and value > 0):
        raise ValueError(f"{name} = {value!r} must be a finite positive number")
    return value


def _clip(x):
    return -1.0 if x < -1.0 else (1.0 if x > 1.0 else x)


def disk_geometry(r, r_sun, earth_radius=WGS84_A, sun_radius=SUN_RADIUS):
    """(a, b, c) in rad: apparent radii of Sun and Earth and their separation seen from r."""
    d = (r_sun[0] - r[0], r_sun[1] - r[1], r_sun[2] - r[2])
    rn = math.sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2])
    dn = math.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
    if not rn > earth_radius:
        raise ValueError(f"r_BN_N: spacecraft distance {rn!r} m from Earth's centre must exceed the Earth "
                         f"radius {earth_radius} m")
    if not dn > sun_radius:
        raise ValueError(f"r_SN_N: Sun distance {dn!r} m from the spacecraft must exceed the Sun radius "
                         f"{sun_radius} m")
    a = math.asin(sun_radius / dn)
    b = math.asin(earth_radius / rn)
    c = math.acos(_clip(-(r[0] * d[0] + r[1] * d[1] + r[2] * d[2]) / (rn * dn)))
    return a, b, c


def sunlit_fraction(r, r_sun, earth_radius=WGS84_A, sun_radius=SUN_RADIUS):
    """Fraction of the Sun's disk visible from r, in [0, 1] (M&G Eq. 3.85-3.87)."""
    a, b, c = disk_geometry(r, r_sun, earth_radius, sun_radius)
    if c >= a + b:
        return 1.0
    if c <= b - a:
        return 0.0
    if c <= a - b:
        return 1.0 - (b * b) / (a * a)
    x = (c * c + a * a - b * b) / (2.0 * c)
    y = math.sqrt(max(a * a - x * x, 0.0))
    area = a * a * math.acos(_clip(x / a)) + b * b * math.acos(_clip((c - x) / b)) - c * y
    return min(1.0, max(0.0, 1.0 - area / (math.pi * a * a)))


class EarthShadow:
    """Conical Earth shadow; stateless. `evaluate(r, r_sun)` returns
    (sunlit_fraction, umbra, penumbra, orbit_day):
    umbra: fraction == 0; penumbra: 0 < fraction < 1 (the annular case counts as penumbra);
    orbit_day: fraction > day_threshold."""

    def __init__(self, earth_radius=WGS84_A, sun_radius=SUN_RADIUS, day_threshold=DAY_THRESHOLD):
        self.earth_radius = _positive("earth_radius", earth_radius)
        self.sun_radius = _positive("sun_radius", sun_radius)
        day_threshold = float(day_threshold)
        if not (0.0 <= day_threshold < 1.0):
            raise ValueError(f"day_threshold = {day_threshold!r} must be in [0, 1)")
        self.day_threshold = day_threshold

    def fraction(self, r, r_sun):
        return sunlit_fraction(r, r_sun, self.earth_radius, self.sun_radius)

    def evaluate(self, r, r_sun):
        f = self.fraction(r, r_sun)
        return f, f == 0.0, 0.0 < f < 1.0, f > self.day_threshold

    def get_state(self):
        return {}

    def set_state(self, state):
        pass


def beta_angle(r, v, r_sun):
    """Sun beta angle (rad): elevation of the Sun above the orbit plane, asin(h_hat . s_hat)."""
    h = (r[1] * v[2] - r[2] * v[1], r[2] * v[0] - r[0] * v[2], r[0] * v[1] - r[1] * v[0])
    hn = math.sqrt(sum(x * x for x in h))
    sn = math.sqrt(sum(x * x for x in r_sun))
    return math.asin(_clip(sum(h[i] * r_sun[i] for i in range(3)) / (hn * sn)))


def cylindrical_eclipse_fraction(altitude, beta, earth_radius=WGS84_A):
    """Fraction of a circular orbit in a cylindrical Earth shadow:
    (1/pi) acos(sqrt(h^2 + 2 R h) / ((R + h) cos beta)) for |beta| < asin(R / (R + h)), else 0."""
    R, h = earth_radius, altitude
    if abs(beta) >= math.asin(R / (R + h)):
        return 0.0
    return math.acos(math.sqrt(h * h + 2.0 * R * h) / ((R + h) * math.cos(beta))) / math.pi
