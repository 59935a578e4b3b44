"""Atmosphere density models for drag: one interface, four models.

    MODELS = ("exponential", "harris_priester", "msis", "jacchia_roberts")
    model = make_density_model(name, space_weather=None, inclination=None, hp_exponent=None)
    model.density(r_N, jd_utc)                 # kg/m^3 at the N position r_N (m), UTC Julian date
    model.kernel(r, jd, model.kernel_data)     # the same number from numba code (None for msis)

Every model converts the inertial position itself: Earth-fixed frame by GMST rotation and WGS-84
geodetic latitude/longitude/altitude, exactly as components.geodesy (the kernels call numba
compilations of the same functions, components.geodesy.geodetic_from_earth_fixed and
components.magnetic_field.gmst), and the Sun, where a model needs it, from the low-precision
formulae of components.sun (also compiled from the same function).

- exponential: Vallado, Fundamentals of Astrodynamics, Table 8-4 (piecewise exponential,
  0-1000 km, geodetic altitude; rho = rho0 exp(-(h - h0)/H) in the band of the largest
  h0 <= h; below 0 km the first band, above 1000 km the last band, as Vallado does).
  Static: no time, no space weather.
- harris_priester: Montenbruck and Gill, Satellite Orbits, section 3.5.2 and Table 3.8 (mean
  solar activity). rho = rho_min(h) + (rho_max(h) - rho_min(h)) cos^n(psi/2), min and max
  interpolated exponentially between the table altitudes, psi the angle between the position
  and the apex of the diurnal bulge (the Sun's direction with its right ascension advanced by
  the 30 deg lag). The table spans 100-1000 km; outside it the end bands are extrapolated
  exponentially (M&G return zero there; a propagator needs a positive, continuous density).
  Exponent n: `hp_exponent` when given (2..6), otherwise from the inclination, linear from
  n = 2 at 0 deg to n = 6 at 90 deg (retrograde orbits use 180 deg - i), and n = 4 (M&G's
  usual value) when neither is given.
- msis: NRLMSIS 2.1 through pymsis (see MsisModel).
- jacchia_roberts: Jacchia 1970 evaluated with Roberts' analytic integration, as in GMAT and
  FreeFlyer (components.jacchia_roberts).

Tables: copied from the shared reference data (Vallado Table 8-4 as in GMAT
ExponentialAtmosphere, with GMAT's corrected 350 km density 9.518e-12; Montenbruck and Gill
Table 3.8 as in Orekit HarrisPriester).
"""
import math

import numpy as np
from numba import njit

from . import geodesy, magnetic_field, sun
from .time_utils import DAYS_PER_CENTURY, J2000_JD

MODELS = ("exponential", "harris_priester", "msis", "jacchia_roberts")

# ---- kernels' geometry: numba compilations of the product's own functions --------------------
geodetic_nb = njit(cache=False)(geodesy.geodetic_from_earth_fixed)
gmst_nb = njit(cache=False)(magnetic_field.gmst)
sun_position_au_nb = njit(cache=False)(sun.sun_position_au)


@njit(cache=False)
def earth_fixed(r, jd):
    """r_E = R3(GMST) r_N (tuple), GMST of the UTC Julian date jd."""
    th = gmst_nb((jd - J2000_JD) / DAYS_PER_CENTURY)
    c, s = math.cos(th), math.sin(th)
    return (c * r[0] + s * r[1], -s * r[0] + c * r[1], r[2])


@njit(cache=False)
def geodetic(r, jd):
    """(geodetic latitude rad, east longitude rad, geodetic altitude m) of the N position r."""
    return geodetic_nb(earth_fixed(r, jd))


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


# ---- exponential (Vallado Table 8-4) ----------------------------------------------------------
# base altitude km, nominal density kg/m^3, scale height km
VALLADO_TABLE = (
    (0, 1.225, 7.249), (25, 3.899e-2, 6.349), (30, 1.774e-2, 6.682), (40, 3.972e-3, 7.554),
    (50, 1.057e-3, 8.382), (60, 3.206e-4, 7.714), (70, 8.770e-5, 6.549), (80, 1.905e-5, 5.799),
    (90, 3.396e-6, 5.382), (100, 5.297e-7, 5.877), (110, 9.661e-8, 7.263), (120, 2.438e-8, 9.473),
    (130, 8.484e-9, 12.636), (140, 3.845e-9, 16.149), (150, 2.070e-9, 22.523), (180, 5.464e-10, 29.740),
    (200, 2.789e-10, 37.105), (250, 7.248e-11, 45.546), (300, 2.418e-11, 53.628), (350, 9.518e-12, 53.298),
    (400, 3.725e-12, 58.515), (450, 1.585e-12, 60.828), (500, 6.967e-13, 63.822), (600, 1.454e-13, 71.835),
    (700, 3.614e-14, 88.667), (800, 1.170e-14, 124.64), (900, 5.245e-15, 181.05), (1000, 3.019e-15, 268.00),
)


@njit(cache=False)
def exponential_kernel(r, jd, data):
    h0, rho0, scale = data
    h = geodetic(r, jd)[2]
    i = np.searchsorted(h0, h, side="right") - 1
    if i < 0:
        i = 0
    return rho0[i] * math.exp(-(h - h0[i]) / scale[i])


class ExponentialModel(DensityModel):
    name = "exponential"

    def __init__(self):
        t = np.array(VALLADO_TABLE, dtype=np.float64)
        self.kernel = exponential_kernel
        self.kernel_data = (t[:, 0] * 1e3, t[:, 1].copy(), t[:, 2] * 1e3)


# ---- Harris-Priester (Montenbruck and Gill Table 3.8) -----------------------------------------
# altitude km, minimum density, maximum density (kg/m^3), mean solar activity
HARRIS_PRIESTER_TABLE = (
    (100, 4.974e-07, 4.974e-07), (120, 2.490e-08, 2.490e-08), (130, 8.377e-09, 8.710e-09),
    (140, 3.899e-09, 4.059e-09), (150, 2.122e-09, 2.215e-09), (160, 1.263e-09, 1.344e-09),
    (170, 8.008e-10, 8.758e-10), (180, 5.283e-10, 6.010e-10), (190, 3.617e-10, 4.297e-10),
    (200, 2.557e-10, 3.162e-10), (210, 1.839e-10, 2.396e-10), (220, 1.341e-10, 1.853e-10),
    (230, 9.949e-11, 1.455e-10), (240, 7.488e-11, 1.157e-10), (250, 5.709e-11, 9.308e-11),
    (260, 4.403e-11, 7.555e-11), (270, 3.430e-11, 6.182e-11), (280, 2.697e-11, 5.095e-11),
    (290, 2.139e-11, 4.226e-11), (300, 1.708e-11, 3.526e-11), (320, 1.099e-11, 2.511e-11),
    (340, 7.214e-12, 1.819e-11), (360, 4.824e-12, 1.337e-11), (380, 3.274e-12, 9.955e-12),
    (400, 2.249e-12, 7.492e-12), (420, 1.558e-12, 5.684e-12), (440, 1.091e-12, 4.355e-12),
    (460, 7.701e-13, 3.362e-12), (480, 5.474e-13, 2.612e-12), (500, 3.916e-13, 2.042e-12),
    (520, 2.819e-13, 1.605e-12), (540, 2.042e-13, 1.267e-12), (560, 1.488e-13, 1.005e-12),
    (580, 1.092e-13, 7.997e-13), (600, 8.070e-14, 6.390e-13), (620, 6.012e-14, 5.123e-13),
    (640, 4.519e-14, 4.121e-13), (660, 3.430e-14, 3.325e-13), (680, 2.632e-14, 2.691e-13),
    (700, 2.043e-14, 2.185e-13), (720, 1.607e-14, 1.779e-13), (740, 1.281e-14, 1.452e-13),
    (760, 1.036e-14, 1.190e-13), (780, 8.496e-15, 9.776e-14), (800, 7.069e-15, 8.059e-14),
    (840, 4.680e-15, 5.741e-14), (880, 3.200e-15, 4.210e-14), (920, 2.210e-15, 3.130e-14),
    (960, 1.560e-15, 2.360e-14), (1000, 1.150e-15, 1.810e-14),
)
HP_LAG = math.radians(30.0)  # the bulge apex leads the Sun by 30 deg in right ascension (about 2 h local time)
HP_EXPONENT_RANGE = (2.0, 6.0)


def hp_exponent_from_inclination(inclination):
    """n = 2 + 4 i'/90 deg with i' = min(i, 180 deg - i): 2 equatorial, 6 polar."""
    i = float(inclination)
    if not (0.0 <= i <= math.pi):
        raise ValueError(f"inclination = {inclination!r} rad must be in [0, pi]")
    i = min(i, math.pi - i)
    return 2.0 + 4.0 * i / (math.pi / 2.0)


@njit(cache=False)
def harris_priester_kernel(r, jd, data):
    h_tab, rho_min, rho_max, n, lag = data
    h = geodetic(r, jd)[2]
    m = h_tab.shape[0]
    i = np.searchsorted(h_tab, h, side="right") - 1
    if i < 0:
        i = 0
    if i > m - 2:
        i = m - 2
    dh = h_tab[i] - h
    hm = (h_tab[i] - h_tab[i + 1]) / math.log(rho_min[i + 1] / rho_min[i])
    hx = (h_tab[i] - h_tab[i + 1]) / math.log(rho_max[i + 1] / rho_max[i])
    dmin = rho_min[i] * math.exp(dh / hm)
    dmax = rho_max[i] * math.exp(dh / hx)
    s = sun_position_au_nb((jd - J2000_JD) / DAYS_PER_CENTURY)
    ra = math.atan2(s[1], s[0])
    dec = math.atan2(s[2], math.sqrt(s[0] * s[0] + s[1] * s[1]))
    cd = math.cos(dec)
    ex, ey, ez = cd * math.cos(ra + lag), cd * math.sin(ra + lag), math.sin(dec)
    rr = math.sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2])
    c_psi = (ex * r[0] + ey * r[1] + ez * r[2]) / rr
    c2 = 0.5 * (1.0 + c_psi)  # cos^2(psi/2)
    if c2 < 0.0:
        c2 = 0.0
    return dmin + (dmax - dmin) * c2 ** (0.5 * n)


class HarrisPriesterModel(DensityModel):
    name = "harris_priester"

    def __init__(self, inclination=None, hp_exponent=None):
        if hp_exponent is not None:
            n = float(hp_exponent)
            lo, hi = HP_EXPONENT_RANGE
            if not (lo <= n <= hi):
                raise ValueError(f"hp_exponent = {hp_exponent!r} must be in [{lo:g}, {hi:g}]")
        elif inclination is not None:
            n = hp_exponent_from_inclination(inclination)
        else:
            n = 4.0
        self.exponent = n
        t = np.array(HARRIS_PRIESTER_TABLE, dtype=np.float64)
        self.kernel = harris_priester_kernel
        self.kernel_data = (t[:, 0] * 1e3, t[:, 1].copy(), t[:, 2].copy(), n, HP_LAG)


# ---- factory ----------------------------------------------------------------------------------
def _default_space_weather(space_weather):
    if space_weather is not None:
        return space_weather
    from .space_weather import SpaceWeather
    return SpaceWeather.from_file()


def make_density_model(name, space_weather=None, inclination=None, hp_exponent=None):
    """The density model `name` (one of MODELS). `space_weather`: a components.space_weather
    source (default: the bundled CSSI file), used by msis and jacchia_roberts; `inclination`
    (rad) and `hp_exponent` are used by harris_priester only."""
    if name not in MODELS:
        raise ValueError(f"density model {name!r} is unknown; choose one of {', '.join(MODELS)}")
    if name == "exponential":
        return ExponentialModel()
    if name == "harris_priester":
        return HarrisPriesterModel(inclination, hp_exponent)
    if name == "msis":
        return MsisModel(_default_space_weather(space_weather))
    from .jacchia_roberts import JacchiaRobertsModel
    return JacchiaRobertsModel(_default_space_weather(space_weather))


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
        date = np.datetime64("1970-01-01T00:00:00") + np.timedelta64(round((jd - 2440587.5) * 86400e6), "us")
        out = pymsis.calculate(np.array([date]), np.array([math.degrees(lon)]), np.array([math.degrees(lat)]),
                               np.array([h / 1e3]), np.array([f107]), np.array([f107a]), np.array(aps),
                               version=2.1)
        return float(out[0, 0])  # Variable.MASS_DENSITY, kg/m^3


# ---- a density model on the simulation clock (what the Atmosphere FMU wraps) -------------------
class AtmosphereAtEpoch:
    """A density model evaluated at simulation time t (s since `epoch`, ISO 8601 UTC).

    State: the time t only (the model itself is fixed by its parameters)."""

    def __init__(self, model, epoch, t0=0.0):
        from . import time_utils

        self.model = model
        self.epoch = time_utils.parse_epoch(epoch, "epoch")
        self._jd_epoch = time_utils.julian_date(self.epoch)
        self.t = time_utils.check_time(t0, "start time")
        sw = getattr(model, "space_weather", None)
        if sw is not None:  # an epoch before the space-weather data is an error now, not mid-run
            try:
                sw._row(self.jd())
            except ValueError as exc:
                raise ValueError(f"epoch = {epoch!r}: {exc}") from None

    def jd(self, t=None):
        return self._jd_epoch + (self.t if t is None else float(t)) / 86400.0

    def density(self, r_N):
        """kg/m^3 at the N position r_N (m) at the current time."""
        return self.model.density(r_N, self.jd())

    def altitude(self, r_N):
        """Geodetic altitude (m, WGS-84) of r_N at the current time."""
        return geodesy.geodetic_from_inertial(tuple(_as_position(r_N)), self.jd())[2]

    def advance_to(self, t):
        from . import time_utils

        self.t = time_utils.check_time(t, "time")

    def get_state(self):
        return {"t": self.t}

    def set_state(self, state):
        self.advance_to(state["t"])
