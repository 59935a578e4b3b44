"""NRLMSIS 2.1 through pymsis, with every space-weather index passed explicitly.

pymsis is needed only when this model is chosen; without it the model refuses to be built with a
message naming the package and how to install it. Its kernel calls pymsis from compiled code
(numba's object mode), so the orbit integrators run the same code for every density model."""
import itertools
import math
import weakref

import numpy as np

from ...core.constants import DAY
from ...core.jit import njit, objmode
from .. import geodesy
from .base import DensityModel, _as_jd, _as_position

# The models the kernel can reach: kernel_data carries the model's key (numba passes numbers,
# not Python objects, into compiled code).
_MODELS = weakref.WeakValueDictionary()
_KEYS = itertools.count(1)


def _density_of(key, r, jd):
    return _MODELS[int(key)].density(r, jd)


@njit(cache=False)
def msis_kernel(r, jd, data):
    """Density (kg/m^3) of the MsisModel whose key is data[0][0]."""
    with objmode(rho="float64"):
        rho = _density_of(data[0][0], r, jd)
    return rho


class MsisModel(DensityModel):
    """NRLMSIS 2.1 (pymsis.calculate, version 2.1) at the geodetic position, with F10.7 of the
    previous day and the 81-day centred F10.7 (observed flux, what NRLMSIS was fitted to) and
    the daily Ap from `space_weather`, always passed explicitly so that pymsis never looks up
    (or downloads) indices itself. Default switches (geomagnetic activity from the daily Ap)."""

    name = "msis"

    def __init__(self, space_weather):
        try:
            import pymsis
        except ImportError:
            raise ImportError("density_model 'msis' (NRLMSIS 2.1) needs the pymsis package, which is not "
                              "installed in this Python: install it with `python -m pip install pymsis` or "
                              "choose another density_model (exponential, harris_priester, "
                              "jacchia_roberts)") from None
        self._calculate = pymsis.calculate
        self.space_weather = space_weather
        key = next(_KEYS)
        _MODELS[key] = self
        self.kernel = msis_kernel
        self.kernel_data = (np.array([float(key)]),)

    def density(self, r_N, jd_utc):
        r, jd = _as_position(r_N), _as_jd(jd_utc)
        lat, lon, h = geodesy.geodetic_from_inertial(tuple(r), jd)
        sw = self.space_weather
        f107, f107a = sw.f107_previous_day(jd), sw.f107a(jd)
        aps = [sw.msis_ap(jd)]
        date = np.datetime64("1970-01-01T00:00:00") + np.timedelta64(round((jd - 2440587.5) * DAY * 1e6), "us")
        out = self._calculate(np.array([date]), np.array([math.degrees(lon)]), np.array([math.degrees(lat)]),
                              np.array([h / 1e3]), np.array([f107]), np.array([f107a]), np.array(aps),
                              version=2.1)
        return float(out[0, 0])  # Variable.MASS_DENSITY, kg/m^3
