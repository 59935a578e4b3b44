"""FMU `Orbit` (instance `orbit`): Cowell orbit propagation with EGM96 zonal gravity, drag and thrust.

Optionally (gravity_degree, sun_gravity, moon_gravity): the GGM03S spherical-harmonic field to
degree and order 36 in the Earth-fixed frame, and the Sun and Moon as point masses.

Wraps components.orbit.cowell.CowellOrbit (gravity point mass + J2..J6, drag per thesis Eq. 1 with the
velocity relative to the rotating atmosphere, thrust F_B rotated to N with q_BN or along -v when
`retrograde`). Integrated across each communication step with adaptive DOP853 (minutes in coast,
0.5 s in burns: do_step(t, h) lands exactly on t + h). Inputs are held over a step, and every
output is a state output (no direct feedthrough). Same connectors as the orbit-averaged
`OrbitAveraged` FMU, so a system swaps one for the other by replacing one component.

The model keeps simulation time (s since `epoch`) from setup_experiment's start time; the initial
elements are the osculating elements at that time. `reentered` latches once the geodetic altitude
falls below reentry_altitude; the model then holds its state (the system's stop signal).
"""
import math

from neighbor_fmu_support import NeighborSlave
from neighbor_orbit_support import atmosphere_model, impulse_input, orbit_interface

from components.core import jit
from components.orbit import cowell, elements
from components.core import time_utils
from components.core.constants import MU_EARTH, R_EQ


class Orbit(NeighborSlave):
    description = ("Cowell orbit propagator (NEIGHBOR thesis Sec. 2.5, Eq. 1): EGM96 J2..J6 gravity, drag "
                   "with a selectable atmosphere, body-frame or retrograde thrust; adaptive DOP853 across each "
                   "communication step")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.log(f"density and orbit kernels: {jit.describe()}")
        orbit_interface(self, R_EQ + 420e3, MU_EARTH, time_utils.DEFAULT_EPOCH, mean=False)
        self.parameter("zonal_degree", 6, None,
                       "Zonal gravity terms: 0 = point mass only, 2 = J2, ..., 6 = J2..J6 (EGM96)", int)
        self.parameter("drag", True, None, "Atmospheric drag on (false: gravity and thrust only)", bool)

        out = lambda key: (lambda: self.model.outputs()[key])  # noqa: E731
        self.output_array("r_BN_N", 3, out("r_BN_N"), "m", "Spacecraft position relative to Earth's centre in N")
        self.output_array("v_BN_N", 3, out("v_BN_N"), "m/s", "Spacecraft velocity relative to N, in N")
        self.output("altitude", out("altitude"), "m", "Geodetic altitude above the WGS-84 ellipsoid")
        self.output("altitude_spherical", out("altitude_spherical"), "m", "|r| - 6378136.3 m")
        self.output("latitude", out("latitude"), "rad", "Geodetic latitude (WGS-84)")
        self.output("longitude", out("longitude"), "rad", "East longitude (GMST Earth-fixed frame), in (-pi, pi]")
        self.output("sma", out("sma"), "m", "Osculating semi-major axis")
        self.output("ecc", out("ecc"), "1", "Osculating eccentricity")
        self.output("perigee_altitude", out("perigee_altitude"), "m", "Osculating a (1 - e) - 6378136.3 m")
        self.output("apogee_altitude", out("apogee_altitude"), "m", "Osculating a (1 + e) - 6378136.3 m")
        self.output("density", out("density"), "kg/m3",
                    "Atmospheric density at the current position and time (0 when drag is false)")
        self.output("reentered", out("reentered"), None,
                    "Latched true once the geodetic altitude is below reentry_altitude; the model then holds "
                    "its state", bool)
        impulse_input(self)
        # The full gravity field and the third bodies (appended last, issue 56)
        self.parameter("gravity_degree", 0, None,
                       "0: the zonal terms of zonal_degree (EGM96); 2..36: the GGM03S spherical-harmonic field to this "
                       "degree in the Earth-fixed frame (GMST rotation), replacing them", int)
        self.parameter("gravity_order", -1, None, "Highest order of the GGM03S field, 0..gravity_degree; -1: the "
                       "degree (0: its zonal terms only)", int)
        self.parameter("sun_gravity", False, None, "The Sun as a third body (Vallado's low-precision ephemeris, "
                       "about 0.01 deg)", bool)
        self.parameter("moon_gravity", False, None, "The Moon as a third body (Montenbruck and Gill's low-precision "
                       "series, a few arcminutes and about 500 km)", bool)

    def build_model(self):
        v = self.values
        if not (0.0 <= v["inc0"] <= math.pi):
            raise ValueError(f"inc0 = {v['inc0']!r} rad must be in [0, pi]")
        sma, ecc, inc, raan, argp, ta = elements.initial_elements(v, v["mu"])
        density = atmosphere_model(v, inclination=inc, resources=self.resources) if v["drag"] else None
        return cowell.CowellOrbit(
            epoch=v["epoch"], sma0=sma, ecc0=ecc, inc0=inc, raan0=raan, argp0=argp,
            ta0=ta, Cd=v["Cd"], area=v["area"], mass=v["mass"], reentry_altitude=v["reentry_altitude"],
            density_model=density, drag=v["drag"], zonal_degree=v["zonal_degree"], mu=v["mu"], t0=self.start_time,
            gravity_degree=v["gravity_degree"], gravity_order=None if v["gravity_order"] == -1 else v["gravity_order"],
            sun_gravity=v["sun_gravity"], moon_gravity=v["moon_gravity"])

    def do_step(self, current_time, step_size):
        m = self.model
        m.set_inputs(self.vector("F_thrust_B", 3), self.vector("q_BN", 4), self.values["retrograde"],
                     self.values["mass"], self.vector("impulse_B", 3), step_size)
        m.advance_to(current_time + step_size)
        return True
