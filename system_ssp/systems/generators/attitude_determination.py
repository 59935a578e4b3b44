"""Write the attitude-determination system (thesis section 3.3.1) and its parameter files.

    python system_ssp/systems/generate_attitude_determination.py   # needs build/fmus/*.fmu

System `attitude_determination`: a slowly tumbling host (`dynamics`, RigidBody, rk4) seen by a
horizon sensor, a sun sensor, a gyro and a GPS receiver, and the TRIAD attitude determination
`ad`. The orbit and Sun ephemeris are fixed values here: the spacecraft at 420 km altitude on
the N x axis, the Sun at its 2023-01-01T00:00:00Z position (the scenario epoch) from the
Astronomical Almanac's low-precision solar coordinates. They are the start values of the
unconnected position inputs, set in the parameter files. The sensors' `sunlit` input is
unconnected (true); the eclipse scenario sets it false.

Parameter files (component-level, bound in the SSD):
- attitude_determination_initial_state.ssv   dynamics: q0, omega0 (a 1.3 deg/s tumble that
  takes the Sun out of the sun sensor's field of view after about 34 s), rk4;
- attitude_determination_<instance>.ssv      one per sensor and for `ad`: accuracies, seeds,
  mounting and the fixed positions.
Scenario files (component.variable names, applied with parameter_sets=[...]):
- attitude_determination_noise_free.ssv      every sigma and the gyro bias zero;
- attitude_determination_eclipse.ssv         sunlit false from the start, `ad` initialized
  with the true attitude (as if the last fix was at eclipse entry), gyro bias 1e-3 rad/s.
"""
import math


from components.core import constants, rotations
from components.sensing import triad

from ...ssp.writer import vec
from .from_spec import write_system

NAME = "attitude_determination"
AU = constants.ASTRONOMICAL_UNIT  # m
R_BN_N = [constants.WGS84_A + 420e3, 0.0, 0.0]  # 420 km, the thesis' first de-orbit altitude


def sun_position(jd):
    """Geocentric Sun position in N (m), mean equator and equinox of date ~ J2000 axes, from the
    Astronomical Almanac low-precision formula (about 0.01 deg)."""
    n = jd - 2451545.0
    L = math.radians((280.460 + 0.9856474 * n) % 360.0)
    g = math.radians((357.528 + 0.9856003 * n) % 360.0)
    lam = L + math.radians(1.915 * math.sin(g) + 0.020 * math.sin(2 * g))
    eps = math.radians(23.439 - 4e-7 * n)
    R = (1.00014 - 0.01671 * math.cos(g) - 0.00014 * math.cos(2 * g)) * AU
    return [R * math.cos(lam), R * math.cos(eps) * math.sin(lam), R * math.sin(eps) * math.sin(lam)]


R_SN_N = sun_position(2459945.5)  # 2023-01-01T00:00:00Z
SUN_N = [s - r for s, r in zip(R_SN_N, R_BN_N)]
# Initial attitude: the Sun 20 deg off the sun sensor's +x boresight, in the B x-y plane.
_b = (math.cos(math.radians(20.0)), math.sin(math.radians(20.0)), 0.0)
Q0 = list(triad.triad_quaternion(_b, (0.0, 0.0, 1.0), SUN_N, rotations.cross(SUN_N, [-x for x in R_BN_N])))
OMEGA0 = [0.01, 0.005, -0.02]  # rad/s

HORIZON_SIGMA = math.radians(0.25)  # CubeSat IR horizon sensor class (thesis [40], CubeSpace CubeIR)
SUN_SIGMA = math.radians(0.5) / 3.0  # nanoSSOC-D60 (thesis [43]): 0.5 deg 3 sigma
GYRO_SIGMA = 5.5e-4  # BMG160 (thesis [44]) 0.014 deg/s/sqrt(Hz) over 5 Hz (10 Hz sampling)
GPS_SIGMA = 1.5  # OEM7700 (thesis [45]) 1.5 m RMS single point
STEP = 0.1

FILES = {
    "initial_state": ("dynamics: initial attitude and slow tumble, rk4",
                      {**vec("q0", Q0), **vec("omega0", OMEGA0), "integrator": "rk4"}),
    "horizon": ("horizon: accuracy, seed, fixed spacecraft position",
                {"sigma": HORIZON_SIGMA, "seed": 1, **vec("r_BN_N", R_BN_N)}),
    "sun_sensor": ("sun_sensor: mounting, field of view, accuracy, seed, fixed Sun and spacecraft positions",
                   {**vec("boresight_B", [1.0, 0.0, 0.0]), "half_fov": math.radians(60.0), "sigma": SUN_SIGMA,
                    "seed": 2, **vec("r_SN_N", R_SN_N), **vec("r_BN_N", R_BN_N)}),
    "gyro": ("gyro: bias, white noise, seed", {**vec("bias", [0.0, 0.0, 0.0]), "sigma": GYRO_SIGMA, "seed": 3}),
    "gps": ("gps: accuracy, seed, fixed spacecraft position",
            {"sigma": GPS_SIGMA, "seed": 4, "available": True, **vec("r_BN_N", R_BN_N)}),
    "ad": ("ad: sensor accuracies (TRIAD order), fix geometry, initial estimate, fixed Sun position",
           {"nadir_sigma": HORIZON_SIGMA, "sun_sigma": SUN_SIGMA, "min_separation": math.radians(5.0),
            **vec("q0", [0.0, 0.0, 0.0, 1.0]), **vec("r_SN_N", R_SN_N)}),
}

SCENARIOS = {
    "noise_free": ("Noise-free sensors: every sigma and the gyro bias zero",
                   {"horizon.sigma": 0.0, "sun_sensor.sigma": 0.0, "gyro.sigma": 0.0, "gps.sigma": 0.0,
                    **{f"gyro.bias[{i}]": 0.0 for i in (1, 2, 3)}}),
    "eclipse": ("Eclipse from the start: no Sun, ad starts from the true attitude and propagates with a "
                "biased gyro (1e-3 rad/s per axis)",
                {"sun_sensor.sunlit": False, **{f"ad.q0[{i}]": q for i, q in enumerate(Q0, 1)},
                 **{f"gyro.bias[{i}]": b for i, b in enumerate([1e-3, -1e-3, 1e-3], 1)}}),
}


def generate(writer):
    for concern, (description, values) in FILES.items():
        writer.ssv(f"{NAME}_{concern}", description, values)
    for scenario, (description, values) in SCENARIOS.items():
        writer.ssv(f"{NAME}_{scenario}", description, values)
    write_system(writer, NAME)
