"""The solar arrays (components.mission.solar_arrays): the cosine law, the Sun distance, the shadow
and the temperature derating, and one-line refusals. The comparison with Basilisk's
simpleSolarPanel is test_solar_arrays_vs_basilisk.py."""
import math

import numpy as np
import pytest

from components.core.constants import ASTRONOMICAL_UNIT, SOLAR_FLUX_1AU
from components.mission.solar_arrays import SolarArrays

AU = ASTRONOMICAL_UNIT


def test_a_panel_facing_the_sun_at_1_au_gives_flux_times_area_times_efficiency():
    arrays = SolarArrays([[1, 0, 0], [-1, 0, 0], [0, 0, 1]], [0.03, 0.03, 0.06], [0.28, 0.28, 0.3])
    np.testing.assert_allclose(arrays.panel_power([1, 0, 0], AU), [SOLAR_FLUX_1AU * 0.03 * 0.28, 0.0, 0.0])
    tilted = [math.cos(math.radians(60.0)), 0.0, math.sin(math.radians(60.0))]
    p = arrays.panel_power(tilted, AU)
    np.testing.assert_allclose(p, [SOLAR_FLUX_1AU * 0.03 * 0.28 * 0.5, 0.0,
                                   SOLAR_FLUX_1AU * 0.06 * 0.3 * math.sqrt(0.75)])
    assert arrays.power(tilted, AU) == pytest.approx(float(np.sum(p)), rel=1e-15)
    assert arrays.power([1, 0, 0], 2.0 * AU) == pytest.approx(SOLAR_FLUX_1AU * 0.03 * 0.28 / 4.0, rel=1e-15)
    assert arrays.power([1, 0, 0], AU, sunlit_fraction=0.0) == 0.0
    assert arrays.power([1, 0, 0], AU, sunlit_fraction=0.25) == pytest.approx(SOLAR_FLUX_1AU * 0.03 * 0.28 / 4.0)
    assert arrays.power([0, 0, 0], AU) == 0.0  # no Sun heading: no power


def test_temperature_derating():
    arrays = SolarArrays([[0, 1, 0]], [0.01], [0.3], temperature_coefficient=-0.0025)
    full = SOLAR_FLUX_1AU * 0.01 * 0.3
    assert arrays.power([0, 1, 0], AU, 1.0, 301.15) == pytest.approx(full, rel=1e-15)
    assert arrays.power([0, 1, 0], AU, 1.0, 341.15) == pytest.approx(full * 0.9, rel=1e-12)
    assert arrays.power([0, 1, 0], AU, 1.0, 900.0) == 0.0  # derated to nothing, never negative


@pytest.mark.parametrize("kwargs, message", [
    (dict(normals_B=[[0, 0, 0]]), r"normal_B of panel 1 \[0.0, 0.0, 0.0\] must be a finite non-zero vector"),
    (dict(efficiencies=[1.2]), r"efficiency \[1.2\] must be in \[0, 1\]"),
    (dict(areas=[-0.01]), r"area \[-0.01\] must be finite and >= 0 m2"),
    (dict(normals_B=[[1, 0, 0]] * 9, areas=[0.01] * 9, efficiencies=[0.3] * 9), r"panel_count = 9 must be in 1..8"),
])
def test_bad_parameters_are_refused_in_one_line(kwargs, message):
    args = dict(normals_B=[[1, 0, 0]], areas=[0.01], efficiencies=[0.3])
    args.update(kwargs)
    with pytest.raises(ValueError, match=message):
        SolarArrays(**args)


def test_bad_inputs_are_refused_in_one_line():
    arrays = SolarArrays([[1, 0, 0]], [0.01], [0.3])
    with pytest.raises(ValueError, match=r"sunlit_fraction = 1.5 must be in \[0, 1\]"):
        arrays.power([1, 0, 0], AU, 1.5)
    with pytest.raises(ValueError, match="sun_distance = 0.0 must be a finite number > 0 m"):
        arrays.power([1, 0, 0], 0.0)
