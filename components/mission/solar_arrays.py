"""Solar arrays: body-mounted and deployed panels, fixed in the body frame, lit by the Sun through
the attitude and the Earth's shadow (Basilisk's simpleSolarPanel, one per panel).

Panel i (unit normal n_i in B on its cell side, area A_i, efficiency eta_i including the packing
factor) with the unit Sun heading s_B, the Sun distance d and the sunlit fraction nu (EarthShadow):

    P_i = F (1 AU / d)^2 nu A_i eta_i max(0, n_i . s_B) k_T,   k_T = max(0, 1 + c_T (T - T_ref))

F the solar flux at 1 AU, k_T the temperature derating of the cells at temperature T (c_T < 0
for real cells, about -0.002 to -0.005 per K; c_T = 0, the default, turns it off). The panels
do not shadow each other and the Earth's albedo is not counted (both small for a CubeSat's
body-mounted faces; a deployed panel in the body's shade is a geometry this model does not see).
The array's power is the sum over the panels, the Power FMU's `solar_power`.
"""
import math

import numpy as np

from ..core.checks import finite_vector
from ..core.constants import ASTRONOMICAL_UNIT, SOLAR_FLUX_1AU

MAX_PANELS = 8
REFERENCE_TEMPERATURE = 301.15  # K (28 C, the cells' datasheet test condition)


def _nonnegative(name, values, unit):
    v = np.array(values, float)
    if not np.all(np.isfinite(v)) or np.any(v < 0.0):
        raise ValueError(f"{name} {v.tolist()} must be finite and >= 0 {unit}")
    return v


class SolarArrays:
    """SolarArrays(normals_B (N x 3), areas m2, efficiencies, solar_flux W/m2, temperature
    coefficient 1/K, reference temperature K)."""

    def __init__(self, normals_B, areas, efficiencies, solar_flux=SOLAR_FLUX_1AU, temperature_coefficient=0.0,
                 reference_temperature=REFERENCE_TEMPERATURE):
        n = np.array(normals_B, float).reshape(-1, 3)
        if not 1 <= len(n) <= MAX_PANELS:
            raise ValueError(f"panel_count = {len(n)} must be in 1..{MAX_PANELS}")
        lengths = np.linalg.norm(n, axis=1)
        for i, length in enumerate(lengths, 1):
            if not (math.isfinite(length) and length > 0.0):
                raise ValueError(f"normal_B of panel {i} {n[i - 1].tolist()} must be a finite non-zero vector")
        self.normals = n / lengths[:, None]
        self.count = len(n)
        self.areas = _nonnegative("area", finite_vector(areas, self.count, "area", "m2"), "m2")
        self.efficiencies = _nonnegative("efficiency", finite_vector(efficiencies, self.count, "efficiency", "1"), "")
        if np.any(self.efficiencies > 1.0):
            raise ValueError(f"efficiency {self.efficiencies.tolist()} must be in [0, 1]")
        self.solar_flux = float(_nonnegative("solar_flux", [solar_flux], "W/m2")[0])
        self.temperature_coefficient = float(finite_vector([temperature_coefficient], 1, "temperature_coefficient",
                                                           "1/K")[0])
        self.reference_temperature = float(_nonnegative("reference_temperature", [reference_temperature], "K")[0])

    def panel_power(self, sun_heading_B, sun_distance, sunlit_fraction=1.0, temperature=None):
        """P_i (W) per panel (see the module)."""
        s = np.array(finite_vector(sun_heading_B, 3, "sun_heading_B", "1"))
        norm = float(np.linalg.norm(s))
        d = float(sun_distance)
        nu = float(sunlit_fraction)
        if not (math.isfinite(d) and d > 0.0):
            raise ValueError(f"sun_distance = {sun_distance!r} must be a finite number > 0 m")
        if not (0.0 <= nu <= 1.0):
            raise ValueError(f"sunlit_fraction = {sunlit_fraction!r} must be in [0, 1]")
        if norm == 0.0:  # no Sun heading (no ephemeris yet): no power
            return np.zeros(self.count)
        derating = 1.0
        if temperature is not None:
            t = float(temperature)
            if not (math.isfinite(t) and t >= 0.0):
                raise ValueError(f"panel_temperature = {temperature!r} must be a finite number >= 0 K")
            derating = max(0.0, 1.0 + self.temperature_coefficient * (t - self.reference_temperature))
        flux = self.solar_flux * (ASTRONOMICAL_UNIT / d) ** 2 * nu * derating
        cosines = np.maximum(0.0, self.normals @ (s / norm))
        return flux * self.areas * self.efficiencies * cosines

    def power(self, sun_heading_B, sun_distance, sunlit_fraction=1.0, temperature=None):
        """The arrays' power (W), the sum over the panels."""
        return float(np.sum(self.panel_power(sun_heading_B, sun_distance, sunlit_fraction, temperature)))

    def get_state(self):
        return {}  # stateless

    def set_state(self, state):
        pass
