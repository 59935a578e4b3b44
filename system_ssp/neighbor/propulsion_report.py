"""Propulsion report: delta-V, propellant, tank (Eq. 75-77), feed lines (Eq. 78-79, Table 4)
and the propulsion assembly mass (section 3.3.9, Appendix H), from simulated maneuvers.

    neighbor-cosim propulsion [--scenario 420km] [--mission results/mission/summary.json]

The command lives in system_ssp.neighbor.mission (`main_propulsion`), as it may run the mission.
Two columns beside the thesis':
- **worst case**: the thesis' sizing rule (section 3.3.9: detumble + the worst-case slew, case
  3's three 180 deg rotations, + attitude control during the burn, + the burn), with detumble
  case 1 and slew case 3 simulated through the master (`thesis` cases), and the tracking and
  burn propellant of a mission run of the scenario;
- **this mission**: the propellant the mission run itself used (its slew is case 1's).
The mission run is read from --mission (a mission results folder's summary.json) or run here
(orbit-averaged, about a minute). The thesis sizes its tank for the 420 km scenario only, so
the thesis column is empty for the others. After the table the command marks both columns
against the scenario's tank and RCS allowance and prints Tables 8-9, mass and volume
(system_ssp.neighbor.budgets).
"""
from components.mission.neighbor import DEFAULT_SCENARIO, SCENARIOS
from components.orbit import propulsion

from ..errors import SSPError
from ..tools.console import DEFAULT_SSP_DIR
from . import thesis

# Section 3.2, 3.3.9, Appendix H, Table 4 (420 km scenario; display units as printed).
THESIS = {"delta_v_m_s": SCENARIOS[DEFAULT_SCENARIO].thesis["delta_v"],
          "burn_propellant_kg": SCENARIOS[DEFAULT_SCENARIO].thesis["propellant"], "detumble_propellant_g": 2.36,
          "slew_propellant_g": 16.03, "tracking_propellant_g": 4.75, "rcs_propellant_g": 23.14,
          "total_propellant_kg": 0.587, "moles": 3.86, "volume_cm3": 376.4, "inner_radius_cm": 4.48,
          "wall_thickness_cm": 0.41, "outer_radius_cm": 4.88, "outer_volume_cm3": 488.2, "shell_volume_cm3": 111.8,
          "shell_mass_g": 301.9, "tank_and_propellant_g": 888.9, "feed_line_wall_mm": 0.77,
          "feed_lines_mass_g": 210.21, "feed_lines_outer_volume_cm3": 61.35, "nozzles_g": 640.0,
          "subtotal_g": 1739.11, "manifold_g": 347.82, "assembly_g": 2086.93}
ROWS = [  # key, label, format
    ("delta_v_m_s", "burn delta-V (m/s, Eq. 2 from the burn propellant)", "{:.2f}"),
    ("burn_propellant_kg", "burn propellant (kg)", "{:.4f}"),
    ("detumble_propellant_g", "detumble propellant (g)", "{:.3f}"),
    ("slew_propellant_g", "slew propellant (g)", "{:.3f}"),
    ("tracking_propellant_g", "attitude control during the burn (g)", "{:.3f}"),
    ("rcs_propellant_g", "attitude-control propellant (g)", "{:.3f}"),
    ("total_propellant_kg", "total propellant (kg)", "{:.4f}"),
    ("moles", "propellant amount (mol, Eq. 75)", "{:.3f}"),
    ("volume_cm3", "tank inner volume (cm3, Eq. 75)", "{:.1f}"),
    ("inner_radius_cm", "tank inner radius (cm, Eq. 76)", "{:.3f}"),
    ("wall_thickness_cm", "tank wall thickness (cm, Eq. 77)", "{:.4f}"),
    ("outer_radius_cm", "tank outer radius (cm)", "{:.3f}"),
    ("outer_volume_cm3", "tank outer volume (cm3)", "{:.1f}"),
    ("shell_volume_cm3", "tank shell volume (cm3)", "{:.1f}"),
    ("shell_mass_g", "tank shell mass (g, Al 6061-T6)", "{:.1f}"),
    ("tank_and_propellant_g", "tank and propellant (g)", "{:.1f}"),
    ("feed_line_wall_mm", "feed-line wall (mm, Eq. 78)", "{:.3f}"),
    ("feed_lines_mass_g", "feed lines, 16 (g, Table 4)", "{:.2f}"),
    ("feed_lines_outer_volume_cm3", "feed lines outer volume (cm3, Table 4)", "{:.2f}"),
    ("nozzles_g", "nozzles, 16 x 40 g (g)", "{:.1f}"),
    ("subtotal_g", "tank + propellant + lines + nozzles (g)", "{:.2f}"),
    ("manifold_g", "manifold, 20 % (g)", "{:.2f}"),
    ("assembly_g", "propulsion assembly (g)", "{:.2f}"),
]


def sizing(burn_kg, detumble_g, slew_g, tracking_g, mass0=propulsion.MASS0):
    """The section 3.3.9 budget for the given propellant: {key of ROWS: value in display units}."""
    rcs_g = detumble_g + slew_g + tracking_g
    total = burn_kg + rcs_g / 1e3
    tank = propulsion.tank_sizing(total)
    lines = propulsion.feed_lines()
    assembly = propulsion.propulsion_assembly_mass(total)
    return {"delta_v_m_s": propulsion.delta_v_of_propellant(burn_kg, mass0), "burn_propellant_kg": burn_kg,
            "detumble_propellant_g": detumble_g, "slew_propellant_g": slew_g, "tracking_propellant_g": tracking_g,
            "rcs_propellant_g": rcs_g, "total_propellant_kg": total, "moles": tank["moles"],
            "volume_cm3": tank["volume"] * 1e6, "inner_radius_cm": tank["inner_radius"] * 1e2,
            "wall_thickness_cm": tank["wall_thickness"] * 1e2, "outer_radius_cm": tank["outer_radius"] * 1e2,
            "outer_volume_cm3": tank["outer_volume"] * 1e6, "shell_volume_cm3": tank["shell_volume"] * 1e6,
            "shell_mass_g": tank["shell_mass"] * 1e3, "tank_and_propellant_g": tank["tank_and_propellant_mass"] * 1e3,
            "feed_line_wall_mm": lines["wall_thickness"] * 1e3, "feed_lines_mass_g": lines["mass"] * 1e3,
            "feed_lines_outer_volume_cm3": lines["outer_volume"] * 1e6, "nozzles_g": assembly["nozzles"] * 1e3,
            "subtotal_g": assembly["subtotal"] * 1e3, "manifold_g": assembly["manifold"] * 1e3,
            "assembly_g": assembly["total"] * 1e3}


def of_mission(summary):
    """The budget of the propellant a mission run used (its summary dict)."""
    missing = [k for k in ("burn_propellant_kg", "detumble_propellant_g", "slew_propellant_g", "tracking_propellant_g")
               if summary.get(k) is None]
    if missing:
        raise SSPError(f"the mission summary has no {', '.join(missing)}: {summary.get('error', 'incomplete run')}")
    return sizing(summary["burn_propellant_kg"], summary["detumble_propellant_g"], summary["slew_propellant_g"],
                  summary["tracking_propellant_g"])


def worst_case(mission_summary, ssp_dir=DEFAULT_SSP_DIR, cases=None):
    """Section 3.3.9's worst case: detumble case 1 and slew case 3 simulated (thesis runner; now,
    unless `cases` holds their results), attitude control during the burn and the burn from the
    mission run. Returns (budget, cases)."""
    if cases is None or not {"detumble_case1", "slew_case3"} <= set(cases):
        cases = thesis.run_cases(ssp_dir, "euler", cases=("detumble_case1", "slew_case3"))
    failed = [name for name in ("detumble_case1", "slew_case3") if not cases[name].converged]
    if failed:
        raise SSPError(f"thesis case(s) {', '.join(failed)} did not converge: no worst case to size for")
    base = of_mission(mission_summary)
    return sizing(base["burn_propellant_kg"], cases["detumble_case1"].propellant, cases["slew_case3"].propellant,
                  base["tracking_propellant_g"]), cases


def report(worst, mission_budget, scenario):
    thesis_col = THESIS if scenario == DEFAULT_SCENARIO else {}
    lines = [f"Propulsion budget, {scenario} scenario (thesis section 3.3.9, Eq. 75-79, Table 4, Appendix H)",
             "| quantity | worst case (detumble 1 + slew 3 simulated) | this mission | thesis | worst vs thesis |",
             "|---|---|---|---|---|"]
    for key, label, fmt in ROWS:
        ref = thesis_col.get(key)
        w, m = worst.get(key), mission_budget.get(key)
        diff = "-" if ref is None or w is None else f"{100.0 * (w - ref) / ref:+.2f} %"
        lines.append(f"| {label} | {fmt.format(w)} | {fmt.format(m)} | {'-' if ref is None else ref} | {diff} |")
    return "\n".join(lines) + "\n"
