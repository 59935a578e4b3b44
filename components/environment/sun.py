"""Sun position relative to Earth's centre: the low-precision algorithm of the Astronomical
Almanac as given by Vallado, Fundamentals of Astrodynamics and Applications, Algorithm 29
(SUN), good to about 0.01 deg from 1950 to 2050:

    T        = Julian centuries since J2000 (UTC for UT1/TDB, see components.core.time_utils)
    lambda_M = 280.460 deg + 36000.771 deg T                      mean longitude
    M        = 357.5291092 deg + 35999.05034 deg T                mean anomaly
    lambda   = lambda_M + 1.914666471 deg sin M + 0.019994643 deg sin 2M   ecliptic longitude
    r        = 1.000140612 - 0.016708617 cos M - 0.000139589 cos 2M        AU
    eps      = 23.439291 deg - 0.0130042 deg T                    obliquity of the ecliptic
    r_SN_N   = r AU [cos lambda, cos eps sin lambda, sin eps sin lambda]

Frame: the algorithm's result is referred to the mean equator and equinox of date (Vallado's
MOD). We use it as the N frame (J2000 axes) without precessing it: the two differ by the
general precession since 2000 (about 0.32 deg in longitude in 2023), far less than matters for
eclipse timing (about 5 s per orbit) or for Sun pointing at the thesis' accuracy.
AU = 149 597 870 700 m (IAU 2012).
"""
import math

from ..core import time_utils
from ..core.constants import DAY, DAYS_PER_CENTURY

AU = 149_597_870_700.0  # m
DEG = math.pi / 180.0


def sun_position_au(T):
    """Sun position relative to Earth in AU (mean equator/equinox of date), T in Julian
    centuries since J2000. Returns (x, y, z)."""
    lam_m = 280.460 + 36000.771 * T
    M = (357.5291092 + 35999.05034 * T) * DEG
    lam = (lam_m + 1.914666471 * math.sin(M) + 0.019994643 * math.sin(2.0 * M)) * DEG
    r = 1.000140612 - 0.016708617 * math.cos(M) - 0.000139589 * math.cos(2.0 * M)
    eps = (23.439291 - 0.0130042 * T) * DEG
    sl = math.sin(lam)
    return (r * math.cos(lam), r * math.cos(eps) * sl, r * math.sin(eps) * sl)


def ecliptic_longitude(T):
    """Ecliptic longitude lambda of the Sun in rad, in [0, 2 pi)."""
    lam_m = 280.460 + 36000.771 * T
    M = (357.5291092 + 35999.05034 * T) * DEG
    return ((lam_m + 1.914666471 * math.sin(M) + 0.019994643 * math.sin(2.0 * M)) % 360.0) * DEG


def right_ascension_declination(r):
    """(right ascension in [0, 2 pi), declination) in rad of a position vector."""
    ra = math.atan2(r[1], r[0]) % (2.0 * math.pi)
    return ra, math.atan2(r[2], math.hypot(r[0], r[1]))


class SunEphemeris(time_utils.Clock):
    """Position of the Sun relative to Earth, r_SN_N in m, at `t` seconds after `epoch`.

    State: the simulation time t only."""

    def __init__(self, epoch=time_utils.DEFAULT_EPOCH, t0=0.0):
        self.epoch_text = epoch
        self.epoch = time_utils.parse_epoch(epoch, "epoch")
        self._s_j2000 = time_utils.seconds_since_j2000(self.epoch)
        self.t = time_utils.check_time(t0, "start time")
        self._cache = (None, None)

    def centuries(self, t=None):
        t = self.t if t is None else t
        return (self._s_j2000 + t) / (DAY * DAYS_PER_CENTURY)

    def position(self, t=None):
        """r_SN_N in m at time t (default: the current time)."""
        t = self.t if t is None else float(t)
        if self._cache[0] == t:
            return self._cache[1]
        x, y, z = sun_position_au(self.centuries(t))
        r = (x * AU, y * AU, z * AU)
        self._cache = (t, r)
        return r
