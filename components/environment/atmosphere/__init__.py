"""Atmosphere density models for drag: one interface, four models.

    MODELS = ("exponential", "harris_priester", "msis", "jacchia_roberts")
    model = make_density_model(name, space_weather=None, inclination=None, hp_exponent=None)
    model.density(r_N, jd_utc)                 # kg/m^3 at the N position r_N (m), UTC Julian date
    model.kernel(r, jd, model.kernel_data)     # the same number from compiled code (numba, when installed)

Every model converts the inertial position itself: Earth-fixed frame by GMST rotation and WGS-84
geodetic latitude/longitude/altitude, exactly as components.environment.geodesy (the kernels call numba
compilations of the same functions, components.environment.geodesy.geodetic_from_earth_fixed and
components.environment.magnetic_field.gmst), and the Sun, where a model needs it, from the low-precision
formulae of components.environment.sun (also compiled from the same function).

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
  FreeFlyer (components.environment.atmosphere.jacchia_roberts).

Tables: copied from the shared reference data (Vallado Table 8-4 as in GMAT
ExponentialAtmosphere, with GMAT's corrected 350 km density 9.518e-12; Montenbruck and Gill
Table 3.8 as in Orekit HarrisPriester).
"""

from ...core import time_utils
from ...core.constants import DAY
from .. import geodesy
from ..space_weather import SpaceWeather
from .base import DensityModel, _as_position, earth_fixed, geodetic, geodetic_nb, gmst_nb, sun_position_au_nb
from .exponential import VALLADO_TABLE, ExponentialModel, exponential_kernel
from .harris_priester import (HARRIS_PRIESTER_TABLE, HP_EXPONENT_RANGE, HP_LAG, HarrisPriesterModel,
                              harris_priester_kernel, hp_exponent_from_inclination)
from .jacchia_roberts import JacchiaRobertsModel
from .msis import MsisModel

MODELS = ("exponential", "harris_priester", "msis", "jacchia_roberts")

__all__ = ["MODELS", "make_density_model", "DensityModel", "ExponentialModel", "HarrisPriesterModel", "MsisModel",
           "JacchiaRobertsModel", "AtmosphereAtEpoch", "VALLADO_TABLE", "HARRIS_PRIESTER_TABLE", "HP_LAG",
           "HP_EXPONENT_RANGE", "hp_exponent_from_inclination", "exponential_kernel", "harris_priester_kernel",
           "earth_fixed", "geodetic", "geodetic_nb", "gmst_nb", "sun_position_au_nb"]


# ---- factory ----------------------------------------------------------------------------------
def _default_space_weather(space_weather):
    if space_weather is not None:
        return space_weather
    return SpaceWeather.from_file()


def make_density_model(name, space_weather=None, inclination=None, hp_exponent=None):
    """The density model `name` (one of MODELS). `space_weather`: a components.environment.space_weather
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
    return JacchiaRobertsModel(_default_space_weather(space_weather))


# ---- a density model on the simulation clock (what the Atmosphere FMU wraps) -------------------
class AtmosphereAtEpoch:
    """A density model evaluated at simulation time t (s since `epoch`, ISO 8601 UTC).

    State: the time t only (the model itself is fixed by its parameters)."""

    def __init__(self, model, epoch, t0=0.0):
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
        return self._jd_epoch + (self.t if t is None else float(t)) / DAY

    def density(self, r_N):
        """kg/m^3 at the N position r_N (m) at the current time."""
        return self.model.density(r_N, self.jd())

    def altitude(self, r_N):
        """Geodetic altitude (m, WGS-84) of r_N at the current time."""
        return geodesy.geodetic_from_inertial(tuple(_as_position(r_N)), self.jd())[2]

    def advance_to(self, t):
        self.t = time_utils.check_time(t, "time")

    def get_state(self):
        return {"t": self.t}

    def set_state(self, state):
        self.advance_to(state["t"])
