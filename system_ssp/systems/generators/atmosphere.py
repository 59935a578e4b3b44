"""Write the atmosphere system (atmosphere.ssd) and its parameter set.

The density FMU on its own: `orbit` (CircularOrbit, 420 km, 51.6 deg) feeds `atmosphere`
(Atmosphere: Jacchia-Roberts with the bundled CSSI space weather, the de-orbit study's settings)
its position; the run records the density along one day of orbits, sampled every minute. The
orbit FMUs evaluate the same models inside their integrators, so the de-orbit systems carry no
separate Atmosphere component; this system is where the density signal itself is looked at, or
where another atmosphere FMU is swapped in (`neighbor-cosim replace`).
"""
import math

from components.core import time_utils
from .from_spec import write_system

NAME = "atmosphere"
ORBIT = {"altitude": 420e3, "inclination": math.radians(51.6), "raan": 0.0, "arg_latitude0": 0.0}
DENSITY = {"epoch": time_utils.DEFAULT_EPOCH, "density_model": "jacchia_roberts", "space_weather_file": "",
           "use_constant_space_weather": False}


def generate(writer):
    writer.ssv(f"{NAME}_orbit", "Circular 420 km orbit at 51.6 deg (the de-orbit study's start)", ORBIT)
    writer.ssv(f"{NAME}_density", "Jacchia-Roberts with the bundled CSSI space weather from 2023-01-01 (the de-orbit "
               "study's settings)", DENSITY)
    write_system(writer, NAME)
