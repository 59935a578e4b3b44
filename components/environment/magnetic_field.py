"""Earth's magnetic field as a tilted (geocentric) dipole: the first-degree terms of IGRF-13.

Coefficients (IGRF-13 main field, epoch 2020.0; Alken et al., "International Geomagnetic
Reference Field: the thirteenth generation", Earth Planets Space 73:49, 2021, coefficient table):

    g10 = -29404.8 nT, g11 = -1450.9 nT, h11 = 4652.5 nT
    secular variation 2020-2025: dg10 = 5.7, dg11 = 7.4, dh11 = -25.9 nT/yr
    reference radius a = 6371.2 km

The n = 1 part of the IGRF scalar potential (geocentric colatitude theta, east longitude phi):

    V = a (a/r)^2 [g10 cos(theta) + (g11 cos(phi) + h11 sin(phi)) sin(theta)]
      = a^3 (g . r) / r^3,    g = [g11, h11, g10] in the Earth-fixed frame (ECEF, x to 0 deg
                                  longitude, z to the North Pole),

since x = r sin(theta) cos(phi), y = r sin(theta) sin(phi), z = r cos(theta). B = -grad V gives

    B(r) = (a/r)^3 B0 [3 (m . r_hat) r_hat - m],   B0 = |g|,   m = g / B0.

Sign convention (derived, not assumed): m = +[g11, h11, g10] / B0 is the unit vector of the
dipole *moment*, which points into the southern hemisphere (g10 < 0; m ~ -z). The boreal
geomagnetic pole, where the axis leaves the northern hemisphere, is -m: 80.59 deg N,
72.68 deg W for 2020.0 (the centred-dipole pole tabulated by e.g. WHOI, "Centered dipole
geomagnetic poles": 80.59 deg N). The dipole is tilted by acos(-g10/B0) = 9.41 deg from the spin
axis. Checks: at the North Pole m . r_hat ~ -0.987, so B ~ -2 B0 r_hat points down into the
Earth; on the equator B ~ -B0 m points north. B0 = 29806 nT: about 3.0e-5 T at the equator,
6.0e-5 T at the geomagnetic poles (surface).

Frames: the Earth-fixed frame is N rotated about z by the Greenwich mean sidereal time
(IAU 1982 formula, Vallado, Fundamentals of Astrodynamics and Applications, Eq. 3-47):

    GMST = 67310.54841 s + (876600 h + 8640184.812866 s) T + 0.093104 s T^2 - 6.2e-6 s T^3,

T = Julian centuries of UT1 since J2000 (UTC used for UT1, as in components.core.time_utils);
r_ECEF = R3(GMST) r_N. Polar motion, precession and nutation are ignored (N is used as the
true-of-date frame), like the rest of the product's N frame (components.environment.sun).

Secular variation (optional, `secular_variation=True`): g(t) = g(2020.0) + dg (year - 2020.0)
with year the decimal year (Julian years of 365.25 days from 2020-01-01T00:00Z).
Output in tesla (nT * 1e-9).
"""
import math

from ..core import rotations, time_utils
from ..core.constants import DAY, DAYS_PER_CENTURY, DAYS_PER_JULIAN_YEAR

# IGRF-13, epoch 2020.0 (nT) and secular variation 2020.0-2025.0 (nT/yr).
G10, G11, H11 = -29404.8, -1450.9, 4652.5
DG10, DG11, DH11 = 5.7, 7.4, -25.9
R_REF = 6371.2e3  # m, IGRF reference radius
NT = 1e-9  # T per nT
EPOCH_2020 = "2020-01-01T00:00:00Z"
TWO_PI = 2.0 * math.pi


def gmst(T):
    """Greenwich mean sidereal time in rad in [0, 2 pi), T = Julian centuries (UT1) since J2000
    (IAU 1982, Vallado Eq. 3-47)."""
    s = 67310.54841 + (876600.0 * 3600.0 + 8640184.812866) * T + 0.093104 * T * T - 6.2e-6 * T * T * T
    return (s % DAY) / DAY * TWO_PI


def dipole_field(g, r):
    """Field of the n = 1 Gauss coefficients g = (g11, h11, g10) (any field unit) at the
    Earth-fixed position r (m): (a/r)^3 [3 (g . r_hat) r_hat - g], same unit as g."""
    x, y, z = r
    rr = math.sqrt(x * x + y * y + z * z)
    if not rr > 0.0 or not math.isfinite(rr):
        raise ValueError(f"r_BN_N {list(r)} must be a finite, non-zero position")
    ux, uy, uz = x / rr, y / rr, z / rr
    k = (R_REF / rr) ** 3
    gr = 3.0 * (g[0] * ux + g[1] * uy + g[2] * uz)
    return (k * (gr * ux - g[0]), k * (gr * uy - g[1]), k * (gr * uz - g[2]))


def dipole_field_spherical(g10, g11, h11, r, colat, lon):
    """(X north, Y east, Z down) in the unit of the coefficients from the gradient of the n = 1
    IGRF potential in spherical coordinates (the IGRF paper's Eq. 1-2 restricted to n = 1):
    B_r = 2 (a/r)^3 [g10 cos th + (g11 cos ph + h11 sin ph) sin th],
    B_th = (a/r)^3 [g10 sin th - (g11 cos ph + h11 sin ph) cos th],
    B_ph = (a/r)^3 [g11 sin ph - h11 cos ph];  X = -B_th, Y = B_ph, Z = -B_r.
    An independent check of the Cartesian formula."""
    k = (R_REF / r) ** 3
    c, s = math.cos(colat), math.sin(colat)
    e = g11 * math.cos(lon) + h11 * math.sin(lon)
    b_r = 2.0 * k * (g10 * c + e * s)
    b_th = k * (g10 * s - e * c)
    b_ph = k * (g11 * math.sin(lon) - h11 * math.cos(lon))
    return (-b_th, b_ph, -b_r)


class MagneticField:
    """Tilted-dipole geomagnetic field in N (and in B for an attitude) at `t` seconds after
    `epoch`. State: the simulation time t only."""

    def __init__(self, epoch=time_utils.DEFAULT_EPOCH, t0=0.0, secular_variation=False):
        self.epoch_text = epoch
        self.epoch = time_utils.parse_epoch(epoch, "epoch")
        self._s_j2000 = time_utils.seconds_since_j2000(self.epoch)
        self._s_2020 = time_utils.seconds_since_j2000(EPOCH_2020)
        if not isinstance(secular_variation, bool):
            raise ValueError(f"secular_variation = {secular_variation!r} must be true or false")
        self.secular_variation = secular_variation
        self.t = time_utils.check_time(t0, "start time")
        self._coeff_cache = (None, None)
        self._field_cache = (None, None)

    # ---- time ----------------------------------------------------------------------------
    def centuries(self, t=None):
        t = self.t if t is None else t
        return (self._s_j2000 + t) / (DAY * DAYS_PER_CENTURY)

    def decimal_year(self, t=None):
        t = self.t if t is None else t
        return 2020.0 + (self._s_j2000 + t - self._s_2020) / (DAY * DAYS_PER_JULIAN_YEAR)

    def gmst(self, t=None):
        return gmst(self.centuries(t))

    def advance_to(self, t):
        self.t = time_utils.check_time(t, "time")

    # ---- field -----------------------------------------------------------------------------
    def coefficients(self, t=None):
        """(g10, g11, h11) in nT at time t (the 2020.0 values unless secular_variation)."""
        if not self.secular_variation:
            return (G10, G11, H11)
        t = self.t if t is None else t
        if self._coeff_cache[0] == t:
            return self._coeff_cache[1]
        dy = self.decimal_year(t) - 2020.0
        c = (G10 + DG10 * dy, G11 + DG11 * dy, H11 + DH11 * dy)
        self._coeff_cache = (t, c)
        return c

    def field_ecef(self, r_ecef, t=None):
        """B in the Earth-fixed frame (T) at the Earth-fixed position r_ecef (m)."""
        g10, g11, h11 = self.coefficients(t)
        b = dipole_field((g11, h11, g10), r_ecef)
        return (b[0] * NT, b[1] * NT, b[2] * NT)

    def field_N(self, r_N, t=None):
        """B_N (T) at the position r_N (m, N frame) at time t (default: the current time)."""
        t = self.t if t is None else float(t)
        r_N = tuple(float(x) for x in r_N)
        key = (t, r_N)
        if self._field_cache[0] == key:
            return self._field_cache[1]
        if not all(math.isfinite(x) for x in r_N):
            raise ValueError(f"r_BN_N {list(r_N)} must be finite")
        th = self.gmst(t)
        c, s = math.cos(th), math.sin(th)
        # r_ECEF = R3(GMST) r_N
        re = (c * r_N[0] + s * r_N[1], -s * r_N[0] + c * r_N[1], r_N[2])
        be = self.field_ecef(re, t)
        # B_N = R3(-GMST) B_ECEF
        b = (c * be[0] - s * be[1], s * be[0] + c * be[1], be[2])
        self._field_cache = (key, b)  # the FMU reads the three components one by one
        return b

    def field_B(self, r_N, q_BN, t=None):
        """B_B = A(q_BN) B_N (T); q_BN is normalized first (a zero quaternion is an error)."""
        A = rotations.attitude_matrix(rotations.normalized(tuple(float(x) for x in q_BN), "q_BN"))
        b = self.field_N(r_N, t)
        return tuple(A[i][0] * b[0] + A[i][1] * b[1] + A[i][2] * b[2] for i in range(3))

    # ---- full state ------------------------------------------------------------------------
    def get_state(self):
        return {"t": self.t}

    def set_state(self, state):
        self.t = float(state["t"])
        self._coeff_cache = (None, None)
        self._field_cache = (None, None)


def tilt_deg(g10=G10, g11=G11, h11=H11):
    """Angle between the dipole axis and the spin axis, deg."""
    return math.degrees(math.atan2(math.hypot(g11, h11), -g10))


def boreal_pole_deg(g10=G10, g11=G11, h11=H11):
    """(geocentric latitude, east longitude) in deg of the northern geomagnetic pole, -m."""
    b0 = math.sqrt(g10 * g10 + g11 * g11 + h11 * h11)
    return math.degrees(math.asin(-g10 / b0)), math.degrees(math.atan2(-h11, -g11))
