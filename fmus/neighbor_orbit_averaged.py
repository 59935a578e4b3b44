"""FMU `OrbitAveraged` (instance `orbit`): orbit-averaged lifetime propagator (mean elements).

Wraps components.orbit.averaged.OrbitAveraged: mean a, e cos(argp), e sin(argp), i, RAAN and
argp + M under orbit-averaged drag (Gauss equations, quadrature over the eccentric longitude,
density from the selected atmosphere model at each node's 3D position), J2 secular drift, and
thrust through the Gauss equations at the current position (short burns). RK4 with steps of at
most one day ending on UTC midnights, at most 1 km of semi-major-axis change, 10 s while
thrusting; do_step(t, h) lands exactly on t + h for any h.

Same inputs and outputs as the Cowell `Orbit` FMU, so a system swaps one for the other by
replacing one component. Differences in meaning: `sma`, `ecc`, `perigee_altitude` and
`apogee_altitude` are mean (not osculating) values; r_BN_N / v_BN_N are the two-body state of
the mean elements; `reentered` latches once the mean perigee altitude a (1 - e) - 6378136.3 m is
below reentry_altitude, at the crossing time found within the internal step, after which the
model holds its state. Every output is a state output (no direct feedthrough); inputs are held
over a step. The initial Keplerian elements are taken as mean elements.
"""
import math

from neighbor_fmu_support import NeighborSlave
from neighbor_orbit_support import atmosphere_model, impulse_input, orbit_interface

from components.core import jit
from components.orbit import averaged, elements
from components.core import time_utils
from components.core.constants import MU_EARTH, R_EQ


class OrbitAveraged(NeighborSlave):
    description = ("Orbit-averaged lifetime propagator: mean elements under orbit-averaged drag (Gauss "
                   "equations, selectable atmosphere), J2 secular drift and thrust; decades in seconds")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.log(f"density and orbit kernels: {jit.describe()}")
        orbit_interface(self, R_EQ + 420e3, MU_EARTH, time_utils.DEFAULT_EPOCH, mean=True)
        self.parameter("drag", True, None, "Atmospheric drag on (false: J2 and thrust only, density output 0)",
                       bool)
        self.parameter("j2", averaged.J2, "1",
                       "J2 of the secular drift of RAAN, argp and M (EGM96 1.0826e-3), in [0, 0.01]; 0 = none")
        self.parameter("quadrature_nodes", 16, None,
                       "Nodes of the orbit-average quadrature (trapezoidal in eccentric longitude), 8..512", int)
        self.parameter("max_step", 86400.0, "s", "Largest internal integration step (> 0); steps also end on "
                       "UTC midnights")
        self.parameter("max_da_step", 1000.0, "m", "Largest change of the semi-major axis in one internal step (> 0)")
        self.parameter("thrust_step", 10.0, "s", "Largest internal step while the thrust is on (> 0)")

        m = lambda: self.model  # noqa: E731
        self.output_array("r_BN_N", 3, lambda: m().state_vectors()[0], "m",
                          "Spacecraft position relative to Earth's centre in N (two-body, from the mean elements)")
        self.output_array("v_BN_N", 3, lambda: m().state_vectors()[1], "m/s",
                          "Spacecraft velocity relative to N, in N (two-body, from the mean elements)")
        self.output("altitude", lambda: m().geodetic()[2], "m", "Geodetic altitude above the WGS-84 ellipsoid")
        self.output("altitude_spherical", lambda: math.sqrt(sum(x * x for x in m().state_vectors()[0])) - R_EQ,
                    "m", "|r| - 6378136.3 m")
        self.output("latitude", lambda: m().geodetic()[0], "rad", "Geodetic latitude (WGS-84)")
        self.output("longitude", lambda: m().geodetic()[1], "rad",
                    "East longitude (GMST Earth-fixed frame), in (-pi, pi]")
        self.output("sma", lambda: m().sma, "m", "Mean semi-major axis")
        self.output("ecc", lambda: m().ecc, "1", "Mean eccentricity")
        self.output("perigee_altitude", lambda: m().perigee_altitude, "m", "Mean a (1 - e) - 6378136.3 m")
        self.output("apogee_altitude", lambda: m().apogee_altitude, "m", "Mean a (1 + e) - 6378136.3 m")
        self.output("density", lambda: m().density(), "kg/m3",
                    "Atmospheric density at the current position and time (0 when drag is false)")
        self.output("reentered", lambda: m().reentered, None,
                    "Latched true once the mean perigee altitude is below reentry_altitude; the model then "
                    "holds its state", bool)
        impulse_input(self)

    def build_model(self):
        v = self.values
        if not (0.0 <= v["inc0"] <= math.pi):
            raise ValueError(f"inc0 = {v['inc0']!r} rad must be in [1e-4, pi - 1e-4]")
        # a Cartesian start is taken as the mean state (no short-period correction)
        sma, ecc, inc, raan, argp, ta = elements.initial_elements(v, v["mu"])
        density = atmosphere_model(v, inclination=inc, resources=self.resources) if v["drag"] else None
        return averaged.OrbitAveraged(
            density, epoch=v["epoch"], sma0=sma, ecc0=ecc, inc0=inc, raan0=raan, argp0=argp,
            ta0=ta, Cd=v["Cd"], area=v["area"], reentry_altitude=v["reentry_altitude"], mu=v["mu"],
            j2=v["j2"], quadrature_nodes=v["quadrature_nodes"], max_step=v["max_step"],
            max_da_step=v["max_da_step"], thrust_step=v["thrust_step"], t0=self.start_time)

    def do_step(self, current_time, step_size):
        v = self.values
        self.model.advance_to(current_time + step_size, self.vector("F_thrust_B", 3), self.vector("q_BN", 4),
                              v["retrograde"], v["mass"], self.vector("impulse_B", 3))
        return True
