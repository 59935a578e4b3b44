"""The NEIGHBOR mission, defined once: the spacecraft's baseline values, the thesis' de-orbit
scenarios with their published numbers, the systems and parameter sets that fly them, the
guidance-and-control sets and the signals the summaries record.

Everything else reads from here: the model defaults (`components.orbit.propulsion`,
`components.attitude.thruster_control`, the orbit models, the thruster models, the FMU
wrappers' parameter starts), the system generators (`system_ssp.systems.generators`), and the
applications (`system_ssp.neighbor`: mission, de-orbit study, propulsion report, validation,
campaigns). Changing the spacecraft or adding a scenario is one edit here and
`python build_fmus.py && python -m system_ssp.systems` (tests/systems/test_mission_definition.py
checks that the generated files, the FMUs' defaults and the applications agree with this file).

Plain data (no models, no FMI): it imports only the standard library and `components.core`, so
every layer can read it.
"""
from dataclasses import dataclass
import math
from types import MappingProxyType
from typing import Mapping, Optional, Tuple

from ..core.names import element_names as elements
from ..core.time_utils import DEFAULT_EPOCH


@dataclass(frozen=True)
class Spacecraft:
    """The failed 6U host with NEIGHBOR attached, as the thesis sizes it (Table 2, Appendix A)."""
    mass: float = 12.0  # kg, total mass at takeover (Table 2)
    edge_a: float = 0.1  # m, box edge along body y (Appendix A); also the x thruster pairs' spacing
    edge_b: float = 0.2  # m, box edge along body z (Appendix A)
    edge_c: float = 0.3  # m, box edge along body x (Appendix A); also the y and z thruster pairs' arms
    Cd: float = 2.2  # drag coefficient (Table 2)
    drag_area: float = 0.02  # m2, area facing the flow (Table 2)
    isp: float = 42.0  # s, specific impulse of the cold-gas thrusters (Section 3.2, MarCO)
    g0: float = 9.81  # m/s2, standard gravity the thesis uses with Isp (Eq. 3)
    deorbit_thrust_per_thruster: float = 0.025  # N, one main de-orbit thruster (Section 3.2)
    n_deorbit_thrusters: int = 4  # main de-orbit thrusters fired together (0.1 N)
    rcs_thrust: float = 0.025  # N, one RCS thruster (Appendix A)

    @property
    def edges(self) -> Tuple[float, float, float]:
        """(a, b, c): the box edges along body y, z and x, the order of the thesis' Eq. 4."""
        return (self.edge_a, self.edge_b, self.edge_c)


SPACECRAFT = Spacecraft()


@dataclass(frozen=True)
class Facet:
    """A flat outer face of the spacecraft for the drag and solar-pressure disturbances
    (components.attitude.disturbances): unit outward normal and centre in B (m, from the centre of
    mass at takeover), area, drag coefficient, specular and diffuse reflection coefficients."""
    name: str
    normal_B: Tuple[float, float, float]
    area: float
    centre_B: Tuple[float, float, float]
    specular: float
    diffuse: float
    Cd: float = SPACECRAFT.Cd


def _box_facets() -> Tuple[Facet, ...]:
    """The outer faces of the 6U stack (the thesis' box: c = 0.3 m along x, a = 0.1 m along y,
    b = 0.2 m along z, uniform, so its centre is the centre of mass), split where the 2U NEIGHBOR
    module (the -x 0.1 m, at the tank: components.attitude.mass_properties) meets the rest of the
    host. Optical coefficients are assumed, not from the thesis: the host's faces carry
    body-mounted solar cells (specular 0.05, diffuse 0.20, the rest absorbed), the module's
    are bare aluminium alloy (specular 0.20, diffuse 0.40)."""
    a, b, c = SPACECRAFT.edge_a, SPACECRAFT.edge_b, SPACECRAFT.edge_c
    module, host = a, c - a  # lengths along x
    xm, xh = -c / 2 + module / 2, c / 2 - host / 2  # their centres along x
    cells, aluminium = (0.05, 0.20), (0.20, 0.40)
    faces = [Facet("host +x", (1.0, 0.0, 0.0), a * b, (c / 2, 0.0, 0.0), *cells),
             Facet("module -x", (-1.0, 0.0, 0.0), a * b, (-c / 2, 0.0, 0.0), *aluminium)]
    for part, length, x, optics in (("host", host, xh, cells), ("module", module, xm, aluminium)):
        for sign in (1.0, -1.0):
            s = "+" if sign > 0 else "-"
            faces.append(Facet(f"{part} {s}y", (0.0, sign, 0.0), length * b, (x, sign * a / 2, 0.0), *optics))
            faces.append(Facet(f"{part} {s}z", (0.0, 0.0, sign), length * a, (x, 0.0, sign * b / 2), *optics))
    return tuple(Facet(f.name, f.normal_B, round(f.area, 12), tuple(round(x, 12) for x in f.centre_B), f.specular,
                       f.diffuse) for f in faces)


FACETS: Tuple[Facet, ...] = _box_facets()
# Residual magnetic dipole of the failed host with NEIGHBOR (A.m2, B): assumed, of the order
# measured on CubeSats of this size (1e-3 to 5e-2 A.m2); the thesis gives none.
RESIDUAL_DIPOLE_B: Tuple[float, float, float] = (0.005, 0.005, 0.01)


@dataclass(frozen=True)
class Orbit:
    """The host's orbit and the de-orbit's start and end (Section 3.2, Table 3)."""
    inclination_deg: float = 51.6  # ISS-like (Table 3)
    deorbit_epoch: str = DEFAULT_EPOCH  # 2023-01-01, the lifetime study's start, and the burn's in the mission
    reentry_altitude_km: float = 250.0  # the thesis' re-entry point
    density_model: str = "jacchia_roberts"  # with the bundled CSSI space weather

    @property
    def inclination(self) -> float:
        return math.radians(self.inclination_deg)


ORBIT = Orbit()


@dataclass(frozen=True)
class Scenario:
    """A thesis de-orbit case (Section 3.2, Figures 11-13): from `altitude_km` (circular) the burn
    lowers the perigee to `target_perigee_km`. `thesis` holds the published numbers: delta_v (m/s),
    propellant (kg), burn_min, life_no_burn and life_burn (years from the burn's start) and the
    figure."""
    name: str
    altitude_km: float
    target_perigee_km: float
    thesis: Mapping[str, float]


def _scenario(name: str, altitude_km: float, target_perigee_km: float, **thesis: float) -> Scenario:
    return Scenario(name, altitude_km, target_perigee_km, MappingProxyType(thesis))


SCENARIOS: Mapping[str, Scenario] = MappingProxyType({s.name: s for s in (
    _scenario("420km", 420.0, 350.0, delta_v=19.84, propellant=0.564, burn_min=38.74, life_no_burn=4.38,
              life_burn=2.20, figure=11),
    _scenario("475km", 475.0, 350.0, delta_v=35.18, propellant=0.982, burn_min=67.42, life_no_burn=25.04,
              life_burn=3.44, figure=12),
    _scenario("525km", 525.0, 300.0, delta_v=63.21, propellant=1.707, burn_min=117.20, life_no_burn=97.41,
              life_burn=3.19, figure=13),
)})
DEFAULT_SCENARIO = "420km"  # the thesis sizes the tank, power and data budgets for this one

# The systems (system_ssp/systems/<name>.ssd, packed as build/ssp/<name>.ssp) by orbit fidelity:
# the Cowell orbit (Orbit FMU) or the orbit-averaged one (OrbitAveraged, the default: years in seconds).
ORBIT_FMUS: Mapping[str, str] = MappingProxyType({"averaged": "OrbitAveraged", "cowell": "Orbit"})
MISSION_SYSTEMS: Mapping[str, str] = MappingProxyType({"averaged": "neighbor_mission_lifetime",
                                                       "cowell": "neighbor_mission"})
DEORBIT_SYSTEMS: Mapping[str, str] = MappingProxyType({"averaged": "deorbit_lifetime", "cowell": "deorbit"})


def scenario_set(system: str, scenario: str, burn: bool = True) -> str:
    """The parameter set (parameters/<name>.ssv, names component.variable) that puts `system` in
    `scenario`; the de-orbit systems also have one without the burn (the host alone)."""
    return f"{system}_{scenario}" + ("" if burn else "_no_burn")


# Guidance, navigation and control: the parameter set each applies after the scenario's (None:
# the system's own values, the closed loop on the attitude estimator).
GNC_SETS: Mapping[str, Optional[str]] = MappingProxyType({
    "closed-loop": None,
    "closed-loop-truth": "mission_gnc_truth",  # the same loop on the true state
    "thesis": "mission_gnc_thesis",  # the thesis' guidance and control: its published numbers
})
DEFAULT_GNC = "closed-loop"


# What the mission records (rows per nc:Schedule mode) for its summary and figures.
MISSION_RECORD: Tuple[str, ...] = (
    "mission.mode", "mission.phase", "mission.detumble_timeouts", "mission.slew_timeouts",
    "mission.determination_timeouts", "mission.safe_reason", "estimator.bias_resets", "estimator.initialized",
    "estimator.attitude_error", "estimator.rate_error", *elements("estimator.sigma_attitude", 3), "estimator.nees_mean",
    "estimator.nees_over_fraction",
    "host.heartbeat", "orbit.sma", "orbit.altitude", "orbit.perigee_altitude",
    "orbit.apogee_altitude", "orbit.reentered", "ground.visible", "ground.elevation",
    "propulsion.propellant_used", "propulsion.burning", "propulsion.mass", "propulsion.on_fraction",
    "thrusters.propellant_mass", "thrusters.axial_off_time", "thrusters.disabled_mask", "thrusters.fault_time",
    "tracking.attitude_error", "tracking.pointing_error", "power.state_of_charge", "power.energy",
    "power.load_power", "data.storage_used", "data.bytes_lost", "data.overflow", "data.downlinked",
    *elements("dynamics.omega_BN_B", 3), *elements("dynamics.euler123", 3),
    *elements("dynamics.euler_integrated", 3), *elements("dynamics.q_BN", 4), *elements("guidance.q_target_BN", 4),
    "estimator.fixed_without_sun", *elements("disturbances.torque_B", 3))
# What the de-orbit study records for its table and figures.
DEORBIT_RECORD: Tuple[str, ...] = (
    "orbit.sma", "orbit.ecc", "orbit.perigee_altitude", "orbit.apogee_altitude", "orbit.altitude",
    "orbit.reentered", "orbit.density", "propulsion.mass", "propulsion.propellant_used",
    "propulsion.burn_time", "propulsion.burning")


@dataclass(frozen=True)
class Part:
    """A component of NEIGHBOR's self-contained configuration outside the propulsion assembly
    (section 3.8, Tables 8-9): its mass and the box its volume is counted as."""
    name: str
    mass_g: float
    dimensions_mm: Optional[Tuple[float, float, float]]  # None: volume taken as negligible (the harness)

    @property
    def volume_cm3(self) -> float:
        return 0.0 if self.dimensions_mm is None else math.prod(self.dimensions_mm) / 1e3


# Tables 8-9 without the propulsion assembly, whose propellant, tank, feed lines, nozzles and
# manifold the propulsion sizing computes (section 3.3.9) from the propellant the mission needs.
PARTS: Tuple[Part, ...] = (
    Part("horizon sensor", 120.0, (90.0, 92.0, 50.0)),
    Part("sun sensor", 6.5, (43.0, 14.0, 5.90)),
    Part("gyroscope", 0.2, (3.0, 3.0, 0.95)),
    Part("GPS receiver", 31.0, (46.0, 71.0, 8.0)),
    Part("GPS antenna", 100.0, (56.0, 56.0, 7.80)),
    Part("microprocessor", 3.0, (5.30, 5.30, 0.50)),
    Part("UHF transceiver", 24.5, (65.0, 40.0, 6.50)),
    Part("UHF antenna", 33.0, (99.60, 99.60, 7.70)),
    Part("battery", 47.0, (65.0, 18.29, 18.29)),
    Part("harness", 200.0, None),  # "less than 0.2 kg", "minimal volume"
)
ENVELOPE_U = 2.0  # the notional 2 U NEIGHBOR takes in the host (section 3.8); 1 U = 1000 cm3
DATA_STORAGE_LIMIT_B = 0.1e6  # section 3.6: "never exceeds a total of 0.1 MB" (of the 256 kB flash)
