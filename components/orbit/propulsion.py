"""De-orbit propulsion: delta-V, propellant, burn time, tank and feed-line sizing (thesis
Section 3.2 Eq. 2-3, Section 3.3.9 Eq. 74-79 and Table 4, Appendices A, F and H), and the
main-thruster model behind the `Propulsion` FMU.

Library (plain functions, SI units in and out; the thesis quotes km, cm, g):

    dV  = sqrt(mu/r1) (sqrt(2 r2 / (r1 + r2)) - 1)        Eq. 2 (negative when lowering)
    m_p = m0 (1 - exp(-|dV| / (Isp g0)))                  Eq. 3 as in Appendix A
    mdot = F / (Isp g0),  t_burn = m_p / mdot             F = 4 x 25 mN, Isp 42 s, g0 9.81
    m_p = I_t / (Isp g0)                                  Eq. 74
    V = n R T / P,  n = m_p / M                            Eq. 75 (R-236fa, ideal gas)
    V = 4/3 pi r^3,  t_w = P r / (2 sigma_y) SF            Eq. 76-77 (Al 6061-T6 sphere)
    t_w = P D / (2 sigma_y) SF,  V_c = pi r^2 l            Eq. 78-79 (304 SS feed lines)

Rounding: Appendix H carries every intermediate value unrounded (wall thickness 0.4057 cm,
inner radius 4.479 cm, feed-line inner radius 2.4006 mm, outer 3.175 mm); the text rounds
them for display only (0.41 cm, 4.48 cm, 2.4 / 3.18 mm). Unrounded values reproduce every
total of the thesis (shell 301.9 g, outer volume 488.2 cm3, feed lines 210.21 g, 61.35 cm3,
assembly 2086.93 g); with the rounded radii the shell would be 305.4 g and the lines 212 g,
so nothing here rounds.

Thruster model (`MainThrusters`): the de-orbit thrusters fire together along one body axis.
Sign convention: `axis_B` is the direction of the FORCE ON THE SPACECRAFT in B (the exhaust
leaves along -axis_B); the default [1, 0, 0] pushes along +x_B, the long axis (docs/conventions.md).
A retrograde burn therefore needs an attitude with +x_B along -v. While `burn_enable` is true
and the budget is not spent, the thrust is n F axis_B and the mass falls at
mdot = n F / (Isp g0). Thrust stops once m0 - m >= m_p (Appendix F's break test); a step that
crosses the budget burns only for the remaining fraction t = (m_p - used) / mdot, so mass,
propellant and accumulated burn time are exact. The thrust output is read by a master at the
start of a step and held (zero-order hold) over it: in the step that crosses the budget it is
the full thrust for the whole step, so a connected orbit model receives at most one step's
excess impulse n F (h - t) (0.05 N s at the thesis' 0.5 s burn step, 0.3 mm/s on 12 kg);
from the next step on it is zero.

Off-pulsing: the attitude control may switch some de-orbit thrusters off for short times in the
burn (components.attitude.thruster_set). `step` takes their off time as a running total in
thruster-seconds (`off_time`, from the thruster model); the fraction of the thrust the total
took away since the previous step applies to this step's thrust and flow (`on_fraction`), so a
model stepped more slowly than the attitude loop (every 0.495 s in the mission's burn) burns the
attitude loop's average with one of its steps' delay, and the burn lasts longer on the same
propellant. The off time of the step in which the budget runs out is not charged (at most one
step's worth, a fraction of 0.5 s of thrust).
"""
import math

from ..core import checks
from ..core.constants import MU_EARTH, R_EQ
from ..core.checks import positive
from ..mission.neighbor import DEFAULT_SCENARIO, SCENARIOS, SPACECRAFT

# The spacecraft's values, from the mission definition (components.mission.neighbor)
G0 = SPACECRAFT.g0  # m/s^2, thesis Eq. 3
ISP = SPACECRAFT.isp  # s, thesis Section 3.2 (MarCO thruster)
THRUST_PER_THRUSTER = SPACECRAFT.deorbit_thrust_per_thruster  # N
N_THRUSTERS = SPACECRAFT.n_deorbit_thrusters  # de-orbit thrusters fired together (0.1 N)
MASS0 = SPACECRAFT.mass  # kg, host spacecraft total mass (Table 2)

# Appendix H constants
R_GAS = 8.314  # J/(K mol)
MOLAR_MASS_R236FA = 0.15204  # kg/mol
STORAGE_PRESSURE = 25e6  # Pa
STORAGE_TEMPERATURE = 273.15 + 20.0  # K
AL6061_YIELD = 276e6  # Pa
AL6061_DENSITY = 2700.0  # kg/m^3
SS304_YIELD = 205e6  # Pa
SS304_DENSITY = 8000.0  # kg/m^3
FEED_LINE_OD = 6.35e-3  # m (1/4 inch)
SAFETY_FACTOR = 2.0
NOZZLE_MASS = 0.04  # kg each
N_NOZZLES = 16
MANIFOLD_FRACTION = 0.20


def _non_negative(name, value):
    value = float(value)
    if not (math.isfinite(value) and value >= 0.0):
        raise ValueError(f"{name} = {value!r} must be a finite number >= 0")
    return value


# ---- delta-V, propellant, burn time ---------------------------------------------------------
def delta_v_eq2(r1, r2, mu=MU_EARTH):
    """Thesis Eq. 2 (m/s, signed): speed change at r1 that puts the other apside at r2 (m).
    Negative when lowering (r2 < r1)."""
    r1, r2, mu = positive("r1", r1), positive("r2", r2), positive("mu", mu)
    return math.sqrt(mu / r1) * (math.sqrt(2.0 * r2 / (r1 + r2)) - 1.0)


def deorbit_delta_v(altitude_initial, altitude_target, mu=MU_EARTH, earth_radius=R_EQ):
    """|dV| (m/s) of the single retrograde burn from a circular orbit at `altitude_initial` to a
    perigee at `altitude_target` (m above the 6378.1363 km equatorial radius), as Appendix A:
    DeltaV = -sqrt(mu/r1) (sqrt(2 r2/(r1+r2)) - 1). 420 -> 350 km: 19.84 m/s."""
    h1 = positive("altitude_initial", altitude_initial)
    h2 = positive("altitude_target", altitude_target)
    if h2 >= h1:
        raise ValueError(f"altitude_target = {h2!r} m must be below altitude_initial = {h1!r} m")
    R = positive("earth_radius", earth_radius)
    return -delta_v_eq2(R + h1, R + h2, mu)


def propellant_mass(delta_v, mass0=MASS0, isp=ISP, g0=G0):
    """Propellant (kg) for |delta_v| (m/s) from total mass `mass0` (Eq. 3, Appendix A):
    m_p = m0 (1 - exp(-|dV| / (Isp g0)))."""
    dv = abs(float(delta_v))
    if not math.isfinite(dv):
        raise ValueError(f"delta_v = {delta_v!r} must be a finite number of m/s")
    m0, isp, g0 = positive("mass0", mass0), positive("isp", isp), positive("g0", g0)
    return m0 * -math.expm1(-dv / (isp * g0))


def delta_v_of_propellant(propellant, mass0=MASS0, isp=ISP, g0=G0):
    """Inverse of Eq. 3: |dV| (m/s) that `propellant` kg delivers from `mass0`."""
    m0 = positive("mass0", mass0)
    mp = _non_negative("propellant", propellant)
    if mp >= m0:
        raise ValueError(f"propellant = {mp!r} kg must be below mass0 = {m0!r} kg")
    return positive("isp", isp) * positive("g0", g0) * math.log(m0 / (m0 - mp))


def mass_flow(thrust, isp=ISP, g0=G0):
    """Propellant flow (kg/s) at total thrust `thrust` (N): mdot = F / (Isp g0)."""
    return positive("thrust", thrust) / (positive("isp", isp) * positive("g0", g0))


def burn_time(propellant, thrust=N_THRUSTERS * THRUST_PER_THRUSTER, isp=ISP, g0=G0):
    """Burn duration (s) to use `propellant` kg at total thrust `thrust` (N): m_p / mdot."""
    return _non_negative("propellant", propellant) / mass_flow(thrust, isp, g0)


def propellant_from_impulse(impulse, isp=ISP, g0=G0):
    """Eq. 74: m_p = I_t / (Isp g0) (kg) for total impulse I_t (N s)."""
    return _non_negative("impulse", impulse) / (positive("isp", isp) * positive("g0", g0))


def deorbit_scenario(altitude_initial, altitude_target, mass0=MASS0, thrust=N_THRUSTERS * THRUST_PER_THRUSTER,
                     isp=ISP, g0=G0, mu=MU_EARTH, earth_radius=R_EQ):
    """{'delta_v' m/s, 'propellant' kg, 'burn_time' s} of a thesis de-orbit scenario (Sec. 3.2)."""
    dv = deorbit_delta_v(altitude_initial, altitude_target, mu, earth_radius)
    mp = propellant_mass(dv, mass0, isp, g0)
    return {"delta_v": dv, "propellant": mp, "burn_time": burn_time(mp, thrust, isp, g0)}


def mission_scenario(name=DEFAULT_SCENARIO, **spacecraft):
    """`deorbit_scenario` of a scenario of the mission definition (components.mission.neighbor),
    by name; `spacecraft`: deorbit_scenario's keywords (mass0, thrust, isp, g0) when not the baseline."""
    s = SCENARIOS[name]
    return deorbit_scenario(s.altitude_km * 1e3, s.target_perigee_km * 1e3, **spacecraft)


# ---- tank and feed lines (Appendix H) -------------------------------------------------------
def tank_sizing(propellant, molar_mass=MOLAR_MASS_R236FA, pressure=STORAGE_PRESSURE,
                temperature=STORAGE_TEMPERATURE, yield_strength=AL6061_YIELD, safety_factor=SAFETY_FACTOR,
                density=AL6061_DENSITY, r_gas=R_GAS):
    """Spherical tank for `propellant` kg stored as an ideal gas (Eq. 75-77, Appendix H).

    Returns SI values: moles, volume (inner, m3), inner_radius, wall_thickness, outer_radius (m),
    outer_volume, shell_volume (m3), shell_mass, tank_and_propellant_mass (kg).
    0.587 kg: 3.86 mol, 376.4 cm3, r 4.48 cm, t_w 0.41 cm, shell 111.8 cm3 / 301.9 g."""
    mp = positive("propellant", propellant)
    P, T = positive("pressure", pressure), positive("temperature", temperature)
    n = mp / positive("molar_mass", molar_mass)
    V = n * positive("r_gas", r_gas) * T / P
    r_i = (3.0 * V / (4.0 * math.pi)) ** (1.0 / 3.0)
    t_w = P * r_i / (2.0 * positive("yield_strength", yield_strength)) * positive("safety_factor", safety_factor)
    r_o = r_i + t_w
    V_o = 4.0 * math.pi / 3.0 * r_o ** 3
    shell_mass = (V_o - V) * positive("density", density)
    return {"moles": n, "volume": V, "inner_radius": r_i, "wall_thickness": t_w, "outer_radius": r_o,
            "outer_volume": V_o, "shell_volume": V_o - V, "shell_mass": shell_mass,
            "tank_and_propellant_mass": shell_mass + mp}


def feed_line_lengths():
    """The 16 feed-line lengths of Table 4 / Appendix H (m): straight runs from below the
    centred tank, sqrt(10^2+5^2) x4, 10, 5, 10, 5, sqrt(10^2+5^2+5^2) x4, 20, 15, 20, 15 cm."""
    d1 = math.sqrt(10.0 ** 2 + 5.0 ** 2)
    d2 = math.sqrt(10.0 ** 2 + 5.0 ** 2 + 5.0 ** 2)
    cm = [d1] * 4 + [10.0, 5.0, 10.0, 5.0] + [d2] * 4 + [20.0, 15.0, 20.0, 15.0]
    return tuple(x * 1e-2 for x in cm)


def feed_lines(lengths=None, outer_diameter=FEED_LINE_OD, pressure=STORAGE_PRESSURE, yield_strength=SS304_YIELD,
               safety_factor=SAFETY_FACTOR, density=SS304_DENSITY):
    """Feed lines (Eq. 78-79, Table 4). Returns SI values: wall_thickness, inner_radius,
    outer_radius (m); per line (tuples): lengths, material_volumes, outer_volumes (m3), masses (kg);
    totals mass (kg), material_volume, outer_volume (m3). Thesis: 0.77 mm wall, 210.21 g, 61.35 cm3."""
    lengths = feed_line_lengths() if lengths is None else tuple(lengths)
    if not lengths:
        raise ValueError("lengths must list at least one feed line")
    lengths = tuple(positive(f"lengths[{i}]", x) for i, x in enumerate(lengths))
    D = positive("outer_diameter", outer_diameter)
    t_w = (positive("pressure", pressure) * D / (2.0 * positive("yield_strength", yield_strength))
           * positive("safety_factor", safety_factor))
    r_o = 0.5 * D
    r_i = r_o - t_w
    if r_i <= 0.0:
        raise ValueError(f"feed-line wall {t_w!r} m is thicker than the outer radius {r_o!r} m "
                         "(lower pressure or safety_factor, or a stronger material)")
    rho = positive("density", density)
    material = tuple(math.pi * (r_o ** 2 - r_i ** 2) * length for length in lengths)
    outer = tuple(math.pi * r_o ** 2 * length for length in lengths)
    masses = tuple(rho * v for v in material)
    return {"wall_thickness": t_w, "inner_radius": r_i, "outer_radius": r_o, "lengths": lengths,
            "material_volumes": material, "outer_volumes": outer, "masses": masses,
            "mass": sum(masses), "material_volume": sum(material), "outer_volume": sum(outer)}


def propulsion_assembly_mass(propellant, nozzle_mass=NOZZLE_MASS, n_nozzles=N_NOZZLES,
                             manifold_fraction=MANIFOLD_FRACTION, **tank_options):
    """Mass budget (kg) of the propulsion assembly (Section 3.3.9): tank shell + propellant +
    feed lines + nozzles = subtotal (1739.11 g for 0.587 kg), manifold = 20 % of it (347.82 g),
    total (2086.93 g)."""
    tank = tank_sizing(propellant, **tank_options)
    lines = feed_lines()
    nozzles = _non_negative("nozzle_mass", nozzle_mass) * int(n_nozzles)
    subtotal = tank["shell_mass"] + float(propellant) + lines["mass"] + nozzles
    manifold = _non_negative("manifold_fraction", manifold_fraction) * subtotal
    return {"tank_shell": tank["shell_mass"], "propellant": float(propellant), "feed_lines": lines["mass"],
            "nozzles": nozzles, "subtotal": subtotal, "manifold": manifold, "total": subtotal + manifold}


# ---- main de-orbit thrusters ------------------------------------------------------------------
class MainThrusters:
    """The de-orbit thrusters: thrust, flow and mass while `burn_enable` is on, until the
    propellant budget is spent (see the module docstring for the sign convention and the step
    that crosses the budget). State: propellant used, accumulated burn time, the spent flag."""

    def __init__(self, thrust_per_thruster=THRUST_PER_THRUSTER, n_thrusters=N_THRUSTERS, isp=ISP, g0=G0,
                 mass0=MASS0, propellant_budget=None, axis_B=(1.0, 0.0, 0.0)):
        self.thrust_per_thruster = positive("thrust_per_thruster", thrust_per_thruster)
        if isinstance(n_thrusters, bool) or int(n_thrusters) != n_thrusters or int(n_thrusters) < 1:
            raise ValueError(f"n_thrusters = {n_thrusters!r} must be an integer >= 1")
        self.n_thrusters = int(n_thrusters)
        self.isp, self.g0 = positive("isp", isp), positive("g0", g0)
        self.mass0 = positive("mass0", mass0)
        if propellant_budget is None:
            propellant_budget = mission_scenario(mass0=self.mass0, thrust=self.thrust, isp=self.isp,
                                                 g0=self.g0)["propellant"]
        self.budget = positive("propellant_budget", propellant_budget)
        if self.budget >= self.mass0:
            raise ValueError(f"propellant_budget = {self.budget!r} kg must be below mass0 = {self.mass0!r} kg")
        axis = checks.finite_vector(axis_B, 3, "axis_B", "thrust direction in B")
        norm = math.sqrt(sum(x * x for x in axis))
        if abs(norm - 1.0) > 1e-6:
            raise ValueError(f"axis_B {list(axis)} must be a unit vector (|axis_B| = {norm!r})")
        self.axis_B = tuple(x / norm for x in axis)
        self.used = 0.0
        self.burn_time = 0.0
        self.spent = False
        self.on_fraction = 1.0  # of the thrust and flow, over the current step (off-pulsing)
        self.off_seen = 0.0  # the thrusters' off time (thruster-seconds) at the previous step
        self.last_h = 0.0  # the previous step's length: the window of the off time's change

    @property
    def thrust(self):
        """Total thrust magnitude when burning (N)."""
        return self.n_thrusters * self.thrust_per_thruster

    @property
    def mdot_burning(self):
        return self.thrust / (self.isp * self.g0)

    @property
    def mass(self):
        return self.mass0 - self.used

    def mass_with(self, rcs_propellant):
        """Total mass (kg) when the RCS has also drawn `rcs_propellant` (kg) from the shared tank."""
        rcs = float(rcs_propellant)
        if not (math.isfinite(rcs) and 0.0 <= rcs < self.mass):
            raise ValueError(f"rcs_propellant = {rcs_propellant!r} kg must be in [0, {self.mass!r}) (the mass left)")
        return self.mass - rcs

    @property
    def remaining(self):
        return self.budget - self.used

    def burning(self, burn_enable):
        return bool(burn_enable) and not self.spent

    def force_B(self, burn_enable):
        """Force on the spacecraft in B (N): n F axis_B while burning, else zero."""
        if not self.burning(burn_enable):
            return (0.0, 0.0, 0.0)
        f = self.thrust * self.on_fraction
        return tuple(f * x for x in self.axis_B)

    def mdot(self, burn_enable):
        """Propellant flow (kg/s, >= 0) while burning, else 0."""
        return self.mdot_burning * self.on_fraction if self.burning(burn_enable) else 0.0

    def step(self, burn_enable, h, off_time=None):
        """Advance by h seconds with `burn_enable` held over the step; `off_time`: the thrusters'
        running total of off-pulsed thruster-seconds (None: unchanged since the last step)."""
        h = float(h)
        if not (math.isfinite(h) and h >= 0.0):
            raise ValueError(f"step size h = {h!r} s must be finite and >= 0")
        off = self.off_seen if off_time is None else float(off_time)
        if not (math.isfinite(off) and off >= self.off_seen - 1e-9):
            raise ValueError(f"off_time = {off_time!r} s must be a finite running total (>= {self.off_seen!r})")
        window = self.n_thrusters * self.last_h
        self.on_fraction = min(1.0, max(0.0, 1.0 - (off - self.off_seen) / window)) if window > 0.0 else 1.0
        self.off_seen, self.last_h = off, h
        if not self.burning(burn_enable) or h == 0.0:
            return
        rate = self.mdot_burning * self.on_fraction
        if rate == 0.0:
            return
        if rate * h >= self.remaining:
            self.burn_time += self.remaining / rate
            self.used = self.budget  # Appendix F: burn until m0 - m >= m_p
            self.spent = True
        else:
            self.used += rate * h
            self.burn_time += h

    def get_state(self):
        return {"used": self.used, "burn_time": self.burn_time, "spent": self.spent, "on_fraction": self.on_fraction,
                "off_seen": self.off_seen, "last_h": self.last_h}

    def set_state(self, state):
        self.used = float(state["used"])
        self.burn_time = float(state["burn_time"])
        self.spent = bool(state["spent"])
        self.on_fraction = float(state["on_fraction"])
        self.off_seen = float(state["off_seen"])
        self.last_h = float(state["last_h"])


class ImpulseWindow:
    """The mean force over a model's previous step from a running total of impulse (N.s, B): what
    the attitude thrusters push the orbit with besides the propulsion's nominal thrust
    (components.attitude.thruster_set, `impulse`). A model stepped more slowly than the thrusters
    (the orbit every 0.495 s in the maneuvers) applies the thrusters' mean force of its previous
    step over the current one, as MainThrusters takes the off-pulsing: one of its steps late, no
    impulse lost. The force is in B as the thrusters accumulate it; the orbit turns it to N with
    the attitude at its step's start (in the burn the body turns 0.03 deg in a step)."""

    def __init__(self):
        self.seen = None  # the running total at the previous step (None: no step yet)
        self.last_h = 0.0

    def force(self, total, h):
        """The mean force (N, B) to hold over the coming step of h seconds, given the running total now."""
        total = checks.finite_vector(total, 3, "impulse_B", "running total of impulse in B, N.s")
        force = (0.0, 0.0, 0.0)
        if self.seen is not None and self.last_h > 0.0:
            force = tuple((a - b) / self.last_h for a, b in zip(total, self.seen))
        self.seen, self.last_h = total, float(h)
        return force

    def get_state(self):
        return {"seen": None if self.seen is None else list(self.seen), "last_h": self.last_h}

    def set_state(self, state):
        self.seen = None if state["seen"] is None else tuple(state["seen"])
        self.last_h = float(state["last_h"])
