"""What every density model shares: the geometry its numba kernel sees (GMST rotation to the
Earth-fixed frame, WGS-84 geodetic coordinates and the low-precision Sun, compiled from the
product's own functions in components.environment) and the `DensityModel` interface."""
import math

import numpy as np

from ...core.jit import njit
from .. import geodesy, magnetic_field, sun
from ...core.time_utils import DAYS_PER_CENTURY, J2000_JD

# ---- kernels' geometry: numba compilations of the product's own functions --------------------
# Cached (cache=True) like every kernel here: inside an FMU, components.core.jit keeps the compiled
# code across runs, and the Jacchia-Roberts kernels took about 8 s to compile in every run.
geodetic_nb = njit(cache=True)(geodesy.geodetic_from_earth_fixed)
gmst_nb = njit(cache=True)(magnetic_field.gmst)
sun_position_au_nb = njit(cache=True)(sun.sun_position_au)


@njit(cache=True)
def gmst_rotation(jd):
    """(cos, sin) of GMST at the UTC Julian date jd."""
    th = gmst_nb((jd - J2000_JD) / DAYS_PER_CENTURY)
    return math.cos(th), math.sin(th)


@njit(cache=True)
def rotated(r, c, s):
    """R3(GMST) r_N (tuple) with (c, s) = gmst_rotation(jd)."""
    return (c * r[0] + s * r[1], -s * r[0] + c * r[1], r[2])


@njit(cache=True)
def earth_fixed(r, jd):
    """r_E = R3(GMST) r_N (tuple), GMST of the UTC Julian date jd."""
    c, s = gmst_rotation(jd)
    return rotated(r, c, s)


@njit(cache=True)
def geodetic(r, jd):
    """(geodetic latitude rad, east longitude rad, geodetic altitude m) of the N position r."""
    return geodetic_nb(earth_fixed(r, jd))


@njit(cache=True)
def vacuum_kernel(r, jd, data):
    """A kernel of no atmosphere: density 0 (the orbit-averaged model binds it in without drag)."""
    return 0.0


def _as_position(r_N):
    r = np.asarray(r_N, dtype=np.float64).reshape(3)
    if not np.all(np.isfinite(r)) or not (r @ r) > 0.0:
        raise ValueError(f"r_BN_N {list(np.ravel(r_N))} must be a finite, non-zero position in m")
    return r


def _as_jd(jd_utc):
    jd = float(jd_utc)
    if not math.isfinite(jd):
        raise ValueError(f"Julian date {jd_utc!r} must be finite")
    return jd


class DensityModel:
    """Base class: `density` calls the numba kernel, so the two agree to the last bit."""

    name = ""
    kernel = None
    kernel_data = ()

    def density(self, r_N, jd_utc):
        """Mass density in kg/m^3 at the N position r_N (m) at the UTC Julian date jd_utc."""
        return float(self.kernel(_as_position(r_N), _as_jd(jd_utc), self.kernel_data))

    def geodetic(self, r_N, jd_utc):
        """(latitude rad, longitude rad, geodetic altitude m) as the model sees them."""
        return geodesy.geodetic_from_inertial(tuple(_as_position(r_N)), _as_jd(jd_utc))

    def __repr__(self):
        return f"<{type(self).__name__} {self.name!r}>"
