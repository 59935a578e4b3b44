"""Write the sun_eclipse system (.ssd) and its parameter files (.ssv).

    python -c "import build_fmus, pathlib; [build_fmus.build_fmu(pathlib.Path(f'fmus/neighbor_{n}.py'), \
pathlib.Path('build/fmus')) for n in ('circular_orbit', 'sun_ephemeris', 'earth_shadow')]"
    python system_ssp/systems/generate_sun_eclipse.py

System: a circular orbit (`orbit`), the Sun ephemeris (`sun`) and the conical Earth shadow
(`shadow`), wired by name (r_BN_N, r_SN_N). Parameter files:
- sun_eclipse_orbit.ssv    the default orbit: 420 km, 51.6 deg (ISS-like), RAAN 0, u0 0;
- sun_eclipse_epoch.ssv    the scenario epoch (the thesis' start date, 2023-01-01T00:00:00Z);
- sun_eclipse_shadow.ssv   Earth and Sun radii and the orbit-day threshold;
- sun_eclipse_dawn_dusk.ssv  scenario (`component.variable` names): a 700 km Sun-synchronous
  dawn-dusk orbit whose node is 90 deg east of the Sun at the epoch, beta about 75 deg, above
  the 64 deg critical angle, so it never enters the shadow.
Stop time: two orbits of the default orbit; communication step 10 s.
"""
import math


from components.orbit import circular
from components.core import constants
from components.environment import eclipse, sun
from components.core import time_utils
from .from_spec import write_system

EPOCH = time_utils.DEFAULT_EPOCH
ORBIT = {"altitude": 420e3, "inclination": math.radians(51.6), "raan": 0.0, "arg_latitude0": 0.0,
         "mu": constants.MU_EARTH_WGS84, "earth_radius": constants.WGS84_A}
SHADOW = {"earth_radius": constants.WGS84_A, "sun_radius": eclipse.SUN_RADIUS,
          "day_threshold": eclipse.DAY_THRESHOLD}
PERIOD = circular.CircularOrbit(ORBIT["altitude"]).period  # 5576.5 s
STEP = 10.0


def dawn_dusk():
    """700 km Sun-synchronous orbit (i = 98.19 deg from the J2 nodal rate) with its ascending
    node 90 deg east of the Sun's right ascension at the epoch: the orbit plane faces the Sun."""
    ra, _ = sun.right_ascension_declination(sun.SunEphemeris(EPOCH).position())
    a = constants.WGS84_A + 700e3
    j2 = 1.08262668e-3
    rate = 2.0 * math.pi / (365.2422 * 86400.0)  # required nodal rate (rad/s)
    cos_i = -rate / (1.5 * j2 * (constants.WGS84_A / a) ** 2 * math.sqrt(constants.MU_EARTH_WGS84 / a ** 3))
    return {"orbit.altitude": 700e3, "orbit.inclination": math.acos(cos_i),
            "orbit.raan": (ra + math.pi / 2) % (2 * math.pi), "orbit.arg_latitude0": 0.0}


def generate(writer):
    writer.ssv("sun_eclipse_orbit",
               "Circular orbit of the sun_eclipse system: 420 km, 51.6 deg, RAAN 0, u0 0 (SI units)", ORBIT)
    writer.ssv("sun_eclipse_epoch",
               "Scenario epoch (simulation time 0), ISO 8601 UTC: the thesis' start date", {"epoch": EPOCH})
    writer.ssv("sun_eclipse_shadow",
               "Earth and Sun radii (m) and the orbit-day threshold of the conical shadow", SHADOW)
    writer.ssv("sun_eclipse_dawn_dusk",
               "Scenario: 700 km Sun-synchronous dawn-dusk orbit facing the Sun at the epoch (no eclipse)",
               dawn_dusk())
    write_system(writer, "sun_eclipse")
