"""Budgets: what each de-orbit scenario is allowed, and a run's use of it marked within or over;
NEIGHBOR's mass and volume (section 3.8, Tables 8-9) from the propellant a run needs.

The thesis sizes its propellant for the 420 km scenario only (section 3.3.9). Its rule, applied
to each scenario (`allowance`):
- **attitude-control (RCS) propellant** = the detumble (case 1, 2.36 g) + the worst-case slew
  (case 3, three 180 deg rotations, 16.03 g) + attitude control through the burn: 4.75 g for the
  420 km burn of 38.74 min, scaled by the scenario's burn length (the tracking holds the attitude
  for as long as the burn lasts). 23.14 g at 420 km, 26.66 g at 475 km, 32.76 g at 525 km.
- **tank** = the scenario's burn propellant (section 3.2) + its RCS allowance: 0.587 kg at
  420 km (the thesis' tank), 1.009 kg at 475 km, 1.740 kg at 525 km.
Against the spacecraft's own limits, the same for every scenario:
- **battery**: the energy used from deployment to the end of the burn, against the cell's 10.8 Wh
  (section 3.5; the thesis' run used 2.2 Wh);
- **data storage**: the largest amount stored, against the thesis' 0.1 MB (section 3.6, "never
  exceeds"; the flash holds 256 kB, beyond which data is lost).

Tables 8-9 (`mass_table`, `volume_table`): the parts outside the propulsion assembly as the
mission definition lists them (components.mission.neighbor.PARTS), the propulsion assembly from
the section 3.3.9 sizing of a propellant mass (propulsion_report.sizing). Table 9 types the tank
as a 53.10 mm sphere (627.3 cm3), which Eq. 75-77 do not give (a 48.8 mm outer radius, 488.2 cm3,
for the same 0.587 kg): the thesis column keeps the typed value, the simulated columns use the
sized tank.
"""
from dataclasses import asdict, dataclass
from typing import Dict, List, Optional, Sequence, Tuple

from components.mission.neighbor import DATA_STORAGE_LIMIT_B, DEFAULT_SCENARIO, ENVELOPE_U, PARTS, SCENARIOS
from components.mission.power import CELL_CAPACITY

from . import propulsion_report, thesis

WH = 3600.0
THESIS_BURN_MIN = SCENARIOS[DEFAULT_SCENARIO].thesis["burn_min"]  # the burn the 4.75 g of tracking was flown for
THESIS_TRACKING_G = propulsion_report.THESIS["tracking_propellant_g"]
THESIS_MASS_G = 2652.13  # Table 8 total
THESIS_VOLUME_CM3 = 1271.84  # Table 9 total
THESIS_TANK_VOLUME_CM3 = 627.3  # Table 9: "53.10 (radius)"
# Tables 8-9's propulsion rows as typed: section 3.3.9's numbers, but the tank's volume Table 9's own
TYPED = {**propulsion_report.THESIS, "outer_volume_cm3": THESIS_TANK_VOLUME_CM3}


@dataclass(frozen=True)
class Allowance:
    """Section 3.3.9's rule for one scenario (g and kg as the thesis prints them)."""
    scenario: str
    burn_min: float  # the scenario's burn length (section 3.2)
    burn_propellant_kg: float  # the scenario's burn propellant (section 3.2)
    detumble_g: float
    slew_g: float
    tracking_g: float

    @property
    def rcs_g(self) -> float:
        return self.detumble_g + self.slew_g + self.tracking_g

    @property
    def tank_kg(self) -> float:
        return self.burn_propellant_kg + self.rcs_g / 1e3

    def describe(self) -> str:
        return (f"RCS allowance {self.rcs_g:.2f} g = detumble {self.detumble_g:.2f} g + worst-case slew "
                f"{self.slew_g:.2f} g + tracking {THESIS_TRACKING_G:.2f} g x {self.burn_min:.2f}/"
                f"{THESIS_BURN_MIN:.2f} min of burn = {self.tracking_g:.2f} g; tank {self.tank_kg:.4f} kg = burn "
                f"{self.burn_propellant_kg:.3f} kg + RCS allowance (thesis section 3.3.9's rule)")


def allowance(scenario: str) -> Allowance:
    ref = SCENARIOS[scenario].thesis
    return Allowance(scenario, ref["burn_min"], ref["propellant"], thesis.THESIS["detumble_case1"]["propellant"],
                     thesis.THESIS["slew_case3"]["propellant"],
                     THESIS_TRACKING_G * ref["burn_min"] / THESIS_BURN_MIN)


@dataclass(frozen=True)
class Budget:
    name: str
    used: float
    allowed: float
    unit: str
    basis: str

    @property
    def within(self) -> bool:
        return self.used <= self.allowed

    def as_dict(self) -> dict:
        return {**asdict(self), "within": self.within}


def propellant_budgets(budget: Dict[str, float], scenario: str) -> List[Budget]:
    """A propellant budget (propulsion_report.sizing's keys) against the scenario's tank and RCS
    allowance."""
    a = allowance(scenario)
    return [Budget("total propellant", budget["total_propellant_kg"], a.tank_kg, "kg",
                   f"the {scenario} tank: burn {a.burn_propellant_kg:.3f} kg + RCS allowance"),
            Budget("attitude-control (RCS) propellant", budget["rcs_propellant_g"], a.rcs_g, "g",
                   "detumble + worst-case slew + tracking through the burn")]


def of_summary(s: dict) -> List[Budget]:
    """A mission summary's budgets: propellant against the tank, RCS against its allowance,
    battery and data storage against the thesis' limits (those the run reached)."""
    out: List[Budget] = []
    if "propulsion" in s:
        out += propellant_budgets(s["propulsion"], s["scenario"])
    if s.get("energy_used_Wh") is not None:
        out.append(Budget("battery energy to the end of the burn", s["energy_used_Wh"], CELL_CAPACITY / WH, "Wh",
                          "the cell's 10.8 Wh (section 3.5)"))
    if s.get("max_storage_MB") is not None:
        out.append(Budget("largest data storage", s["max_storage_MB"], DATA_STORAGE_LIMIT_B / 1e6, "MB",
                          "the thesis' 0.1 MB (section 3.6)"))
    return out


def lines(budgets: Sequence[dict], title: str) -> List[str]:
    """Markdown rows of budgets (as_dict form), each marked within or OVER."""
    out = [title, "| budget | used | allowed | margin | verdict | basis |", "|---|---|---|---|---|---|"]
    for b in budgets:
        margin = 100.0 * (b["allowed"] - b["used"]) / b["allowed"]
        out.append(f"| {b['name']} ({b['unit']}) | {b['used']:.4g} | {b['allowed']:.4g} | {margin:+.1f} % | "
                   f"{'within' if b['within'] else 'OVER'} | {b['basis']} |")
    return out


def _propulsion_rows(sized: Dict[str, float]) -> Tuple[Dict[str, float], Dict[str, float]]:
    mass = {"propellant": sized["total_propellant_kg"] * 1e3, "propellant tank": sized["shell_mass_g"],
            "propellant feed lines": sized["feed_lines_mass_g"], "thruster nozzles": sized["nozzles_g"],
            "miscellaneous propulsion assembly": sized["manifold_g"]}
    volume = {"propellant tank": sized["outer_volume_cm3"],
              "propellant feed lines": sized["feed_lines_outer_volume_cm3"]}
    return mass, volume


def mass_table(sized: Optional[Dict[str, float]] = None) -> Dict[str, float]:
    """Table 8, {component: g} with "total": the propulsion assembly sized for `sized`
    (propulsion_report.sizing's keys), or as the thesis typed it."""
    rows = {**_propulsion_rows(TYPED if sized is None else sized)[0], **{p.name: p.mass_g for p in PARTS}}
    return {**rows, "total": sum(rows.values())}


def volume_table(sized: Optional[Dict[str, float]] = None) -> Dict[str, float]:
    """Table 9, {component: cm3} with "total" (the harness' volume is negligible: not listed)."""
    parts = {p.name: p.volume_cm3 for p in PARTS if p.dimensions_mm is not None}
    rows = {**_propulsion_rows(TYPED if sized is None else sized)[1], **parts}
    return {**rows, "total": sum(rows.values())}


def _number(value: float) -> str:
    return f"{value:.2f}" if value >= 1.0 else f"{value:.3g}"  # as Tables 8-9 print them


def mass_volume_report(worst: Dict[str, float], mission: Dict[str, float], scenario: str) -> str:
    """Tables 8-9 beside the thesis: the worst case's and this mission's propulsion assembly
    (sized from their propellant); the volume against the 2 U NEIGHBOR may take."""
    text = [f"Mass and volume, {scenario} scenario (thesis section 3.8, Tables 8-9; propulsion sized from "
            "the simulated propellant, section 3.3.9)"]
    for what, table, unit in (("mass", mass_table, "g"), ("volume", volume_table, "cm3")):
        typed, w, m = table(), table(worst), table(mission)
        text += ["", f"| component | {what} ({unit}), worst case | this mission | thesis |", "|---|---|---|---|"]
        text += [f"| {name} | {_number(w[name])} | {_number(m[name])} | {_number(typed[name])} |" for name in typed]
    limit = ENVELOPE_U * 1e3
    text.append("")
    for label, sized in (("worst case", worst), ("this mission", mission)):
        value = volume_table(sized)["total"]
        text.append(f"volume, {label}: {value:.1f} cm3 = {value / 1e3:.2f} U of the {ENVELOPE_U:g} U envelope: "
                    f"{'within' if value <= limit else 'OVER'}")
    text.append(f"(Table 9 types the tank as a 53.10 mm sphere, {THESIS_TANK_VOLUME_CM3} cm3; Eq. 75-77 size "
                "it from the propellant, which the two simulated columns use)")
    return "\n".join(text) + "\n"
