"""FMU `SolarArrays` (instance `solar_arrays`): body-mounted and deployed solar panels fixed in the
body frame, lit through the attitude and the Earth's shadow.

Wraps components.mission.solar_arrays.SolarArrays (one Basilisk simpleSolarPanel per panel):
P_i = F (1 AU / d)^2 nu A_i eta_i max(0, n_i . s_B) k_T with the Sun heading in B and its distance
(SunlineEphemeris), the sunlit fraction (EarthShadow) and an optional temperature derating.
solar_power feeds the Power FMU's solar_power. Stateless: the outputs depend on the inputs.
Slots above panel_count are unused (zero power).
"""
from neighbor_fmu_support import NeighborSlave

from components.core.constants import ASTRONOMICAL_UNIT, SOLAR_FLUX_1AU
from components.core.names import element_names, matrix_names
from components.mission import solar_arrays

N = solar_arrays.MAX_PANELS
_DEFAULT_NORMALS = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1), (1, 0, 0), (0, 1, 0)]


class SolarArrays(NeighborSlave):
    description = ("Solar arrays (up to 8 panels fixed in B): power from the Sun heading in B, the Sun distance, "
                   "the sunlit fraction and the cells' temperature; the Power FMU's solar_power")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("panel_count", 6, None, f"Number of panels, 1..{N} (slots 1..panel_count)", int)
        for i, row in enumerate(matrix_names("normal_B", N, 3)):
            for j in range(3):
                self.parameter(row[j], float(_DEFAULT_NORMALS[i][j]), "1",
                               f"Normal of panel {i + 1}'s cell side in B, normalized (non-zero; component {j + 1})")
        self.parameter_array("area", [0.01] * N, "m2", "Cell area of each panel, >= 0 (default one 10 x 10 cm face)")
        self.parameter_array("efficiency", [0.28] * N, "1",
                             "Conversion efficiency of each panel with its packing factor, in [0, 1]")
        self.parameter("solar_flux", SOLAR_FLUX_1AU, "W/m2", "Solar flux at 1 AU, >= 0")
        self.parameter("temperature_coefficient", 0.0, "1/K",
                       "Power change per kelvin of cell temperature above the reference (0: no derating)")
        self.parameter("reference_temperature", solar_arrays.REFERENCE_TEMPERATURE, "K",
                       "Cell temperature of the rated efficiency, >= 0")
        heading = self.input_array("sun_heading_B", [1.0, 0.0, 0.0], "1",
                                   "Unit vector to the Sun in B (SunlineEphemeris' sun_heading_B)")
        distance = self.input("sun_distance", ASTRONOMICAL_UNIT, "m", "Sun distance, > 0 (SunlineEphemeris)")
        sunlit = self.input("sunlit_fraction", 1.0, "1", "Sunlit fraction of the Sun's disc, in [0, 1] (EarthShadow)")
        temperature = self.input("panel_temperature", solar_arrays.REFERENCE_TEMPERATURE, "K",
                                 "Cell temperature, >= 0 (used with temperature_coefficient)")
        deps = heading + (distance, sunlit, temperature)
        out = lambda: self.feedthrough(self._evaluate)  # noqa: E731
        self.output("solar_power", lambda: float(sum(out())), "W",
                    "Electrical power of the arrays, the sum over the panels (Power's solar_power)", depends_on=deps)
        self.output_array("panel_power", N, out, "W", "Electrical power of each panel", depends_on=deps)

    def build_model(self):
        v = self.values
        count = v["panel_count"]
        if not 1 <= count <= N:
            raise ValueError(f"panel_count = {count} must be in 1..{N}")
        normals = [[v[e] for e in row] for row in matrix_names("normal_B", N, 3)][:count]
        return solar_arrays.SolarArrays(normals, [v[e] for e in element_names("area", N)][:count],
                                        [v[e] for e in element_names("efficiency", N)][:count], v["solar_flux"],
                                        v["temperature_coefficient"], v["reference_temperature"])

    def _evaluate(self):
        v = self.values
        power = self.model.panel_power(self.vector("sun_heading_B", 3), v["sun_distance"], v["sunlit_fraction"],
                                       v["panel_temperature"]).tolist()
        return power + [0.0] * (N - len(power))

    def do_step(self, current_time, step_size):
        return True
