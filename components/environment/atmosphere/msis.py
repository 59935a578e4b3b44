"""NRLMSIS 2.1 through pymsis, with every space-weather index passed explicitly."""
import math

import numpy as np

from ...core.constants import DAY
from .. import geodesy
from .base import DensityModel, _as_jd, _as_position

# ---- NRLMSIS 2.1 ------------------------------------------------------------------------------
class MsisModel(DensityModel):
    """NRLMSIS 2.1 (pymsis.calculate, version 2.1) at the geodetic position, with F10.7 of the
    previous day and the 81-day centred F10.7 (observed flux, what NRLMSIS was fitted to) and
    the daily Ap from `space_weather`, always passed explicitly so that pymsis never looks up
    (or downloads) indices itself. Default switches (geomagnetic activity from the daily Ap).
    No numba kernel (pymsis is Fortran called from Python): `kernel` is None."""

    name = "msis"
    kernel = None
    kernel_data = ()

    def __init__(self, space_weather):
        import pymsis  # noqa: F401 - fail here, not in the first density call, if it is missing

        self.space_weather = space_weather

    def density(self, r_N, jd_utc):
        import pymsis

        r, jd = _as_position(r_N), _as_jd(jd_utc)
        lat, lon, h = geodesy.geodetic_from_inertial(tuple(r), jd)
        sw = self.space_weather
        f107, f107a = sw.f107_previous_day(jd), sw.f107a(jd)
        aps = [sw.msis_ap(jd)]
        date = np.datetime64("1970-01-01T00:00:00") + np.timedelta64(round((jd - 2440587.5) * DAY * 1e6), "us")
        out = pymsis.calculate(np.array([date]), np.array([math.degrees(lon)]), np.array([math.degrees(lat)]),
                               np.array([h / 1e3]), np.array([f107]), np.array([f107a]), np.array(aps),
                               version=2.1)
        return float(out[0, 0])  # Variable.MASS_DENSITY, kg/m^3
