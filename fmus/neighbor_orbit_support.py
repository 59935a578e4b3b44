"""What the FMUs that compute a density share (Atmosphere, Orbit, OrbitAveraged): the atmosphere
parameters and the density model built from them, and the orbit FMUs' connector contract.

A module of its own so that only these FMUs bundle the atmosphere models and the space-weather
file (build_fmus.py bundles what a wrapper imports)."""
import math
import os

from neighbor_fmu_support import in_this_extraction

from components.mission.neighbor import SPACECRAFT


def orbit_interface(slave, default_sma, mu, epoch, mean):
    """Parameters and inputs every orbit FMU shares (the Orbit / OrbitAveraged connector
    contract), so that a system swaps one for the other by replacing a component. `mean`:
    the initial elements are mean elements (orbit-averaged model) rather than osculating."""
    kind = "mean " if mean else ""
    slave.parameter("epoch", epoch, None, "Scenario epoch, ISO 8601 UTC; simulation time is seconds since it",
                    str)
    slave.parameter("sma0", default_sma, "m", f"Initial {kind}semi-major axis (thesis Table 3: 6798.1363 km); "
                    "perigee must be above reentry_altitude")
    slave.parameter("ecc0", 0.0, "1", f"Initial {kind}eccentricity, in [0, 1)")
    slave.parameter("inc0", math.radians(51.6), "rad", "Initial inclination, in [1e-4, pi - 1e-4] (the element "
                    "set is singular for equatorial orbits)" if mean else "Initial inclination, in [0, pi]")
    slave.parameter("raan0", 0.0, "rad", "Initial right ascension of the ascending node")
    slave.parameter("argp0", 0.0, "rad", "Initial argument of perigee (ignored for ecc0 = 0)")
    slave.parameter("ta0", 0.0, "rad",
                    "Initial true anomaly (for ecc0 = 0: argument of latitude from the ascending node)")
    slave.parameter("cartesian0", False, None, "True: start from r0_N and v0_N (osculating state in N) instead of "
                    "the elements sma0 ... ta0", bool)
    a = default_sma
    v = math.sqrt(mu / a)
    slave.parameter_array("r0_N", [a, 0.0, 0.0], "m", "Initial position in N, used when cartesian0 is true")
    slave.parameter_array("v0_N", [0.0, v * math.cos(math.radians(51.6)), v * math.sin(math.radians(51.6))], "m/s",
                          "Initial velocity in N, used when cartesian0 is true (must give a closed orbit)")
    slave.parameter("Cd", SPACECRAFT.Cd, "1", "Drag coefficient (> 0, <= 10; thesis Table 2: 2.2)")
    slave.parameter("area", SPACECRAFT.drag_area, "m2", "Drag area facing the flow (> 0; thesis Table 2: 0.02 m2)")
    slave.parameter("reentry_altitude", 250e3, "m", "Re-entry altitude (thesis: 250 km), compared with the "
                    + ("mean perigee altitude" if mean else "geodetic altitude") + "; an initial perigee "
                    "altitude sma0 (1 - ecc0) - 6378136.3 m below it is an error")
    atmosphere_parameters(slave)
    slave.parameter("mu", mu, "m3/s2", "Earth's gravitational parameter (thesis: 398600.4415 km3/s2), > 0")
    slave.input_array("F_thrust_B", [0.0, 0.0, 0.0], "N",
                      "Thrust force in the body frame B, held over a step (rotated to N with q_BN)")
    slave.input_array("q_BN", [0.0, 0.0, 0.0, 1.0], "1",
                      "Attitude quaternion of B relative to N, scalar last (A(q) maps N to B)")
    slave.input("retrograde", False, None,
                "When true the thrust acts along -v (velocity relative to N) with magnitude |F_thrust_B|, "
                "ignoring q_BN", bool)
    slave.input("mass", SPACECRAFT.mass, "kg", "Spacecraft total mass (> 0), from the propulsion FMU")


def impulse_input(slave):
    """The attitude thrusters' running total of impulse (declared after every other variable of the
    orbit FMUs, so that the earlier value references stay as they were)."""
    slave.input_array("impulse_B", [0.0, 0.0, 0.0], "N.s",
                      "Running total of the attitude thrusters' impulse in B beyond F_thrust_B (the RCS net force, "
                      "the axial thrusters' errors); its mean over the previous step is added to F_thrust_B over "
                      "this one (not with retrograde)")


# ---- atmosphere parameters shared by the Atmosphere, Orbit and OrbitAveraged FMUs ------------
def atmosphere_parameters(slave):
    """Declare the shared atmosphere parameters on a NeighborSlave (same names, units and
    meaning on every FMU that computes a density); `atmosphere_model(slave.values, ...)`
    builds the model from their values."""
    slave.parameter("density_model", "jacchia_roberts", None,
                    "Atmosphere density model: exponential (Vallado Table 8-4), harris_priester (Montenbruck "
                    "and Gill), msis (NRLMSIS 2.1) or jacchia_roberts (Jacchia 1970 / Roberts, as FreeFlyer)", str)
    slave.parameter("space_weather_file", "", None,
                    "CSSI space-weather file (CelesTrak SpaceWx format 1.2) for msis and jacchia_roberts; empty = "
                    "the bundled copy of 2026-08-22 (observed from 2000, predictions to 2041-10, last entry held "
                    "after that)", str)
    slave.parameter("use_constant_space_weather", False, None,
                    "When true, msis and jacchia_roberts use the constant f107, f107a and ap below instead of "
                    "the space-weather file", bool)
    slave.parameter("f107", 150.0, "1",
                    "Constant daily solar flux F10.7 in solar flux units (1 sfu = 1e-22 W/m2/Hz), 50..400; used "
                    "when use_constant_space_weather")
    slave.parameter("f107a", 150.0, "1",
                    "Constant 81-day mean solar flux F10.7 in solar flux units (1 sfu = 1e-22 W/m2/Hz), 50..400; "
                    "used when use_constant_space_weather")
    slave.parameter("ap", 15.0, "1",
                    "Constant geomagnetic index Ap (daily and 3-hourly), 0..400; used when "
                    "use_constant_space_weather")
    slave.parameter("hp_exponent", 0.0, "1",
                    "Harris-Priester cosine exponent n, 2..6 (2 low inclination, 6 polar); 0 = from the orbit "
                    "inclination (linear, 2 at 0 deg to 6 at 90 deg), or 4 where the FMU has no orbit")


_ATMOSPHERE_CACHE = {}


def atmosphere_model(values, inclination=None, resources=None):
    """The components.environment.atmosphere density model for the parameter values declared by
    `atmosphere_parameters` (a mapping name -> value, e.g. slave.values). `inclination` (rad)
    sets the Harris-Priester exponent when hp_exponent is 0; `resources`: the instance's resources
    folder (the bundled space-weather file is read from there). ValueError naming the parameter
    for a bad value. A space-weather file is parsed once per path and process."""
    from components.environment import atmosphere, space_weather

    name = values["density_model"]
    if name not in atmosphere.MODELS:
        raise ValueError(f"density_model = {name!r} is unknown; choose one of {', '.join(atmosphere.MODELS)}")
    n = float(values["hp_exponent"])
    if n != 0.0 and not (2.0 <= n <= 6.0):
        raise ValueError(f"hp_exponent = {n!r} must be 0 (from the inclination) or in [2, 6]")
    sw = None
    if name in ("msis", "jacchia_roberts"):
        if values["use_constant_space_weather"]:
            sw = space_weather.ConstantSpaceWeather(values["f107"], values["f107a"], values["ap"])
        else:
            path = values["space_weather_file"]
            key = os.path.abspath(path) if path else ""
            if key and not os.path.isfile(key):
                raise ValueError(f"space_weather_file = {path!r} does not exist")
            if key not in _ATMOSPHERE_CACHE:
                try:
                    default = in_this_extraction(space_weather.BUNDLED_FILE, space_weather, resources)
                    _ATMOSPHERE_CACHE[key] = space_weather.SpaceWeather.from_file(path or default)
                except ValueError as exc:
                    raise ValueError(f"space_weather_file = {path!r}: {exc}") from None
            sw = _ATMOSPHERE_CACHE[key]
    return atmosphere.make_density_model(name, space_weather=sw, inclination=inclination,
                                         hp_exponent=None if n == 0.0 else n)
