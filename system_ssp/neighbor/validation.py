"""Every published thesis number the product reproduces, in one table: the published value, ours,
the difference, the tolerance, and the test that guards it.

    neighbor-cosim validation [--markdown docs/validation.md] [--json FILE]

NUMBERS is the table. Its tolerances are the ones the tests apply: a guarding test calls
`assert_reproduces(key, ours)`, and the suite fails when a number of the table was not checked
by the test the table names (tests/conftest.py). The command runs the thesis cases, the 420 km
mission, the worst-case propulsion budget and the de-orbit study (orbit-averaged, full
lifetimes), a few minutes in all, prints the table and, with --markdown, rewrites the generated
block of docs/validation.md.
"""
from dataclasses import dataclass
import json
import math
import os
from pathlib import Path
import re
import sys
from typing import Any, Dict

from components.mission.neighbor import DEFAULT_SCENARIO

from ..atomic import write_text_atomic
from ..builder import resolve_system
from ..errors import SSPError
from ..master.result import check_output_file
from ..tools.console import ArgumentParser, DEFAULT_SSP_DIR, add_console_arguments, console_settings
from . import deorbit_study, mission, propulsion_report, thesis


@dataclass(frozen=True)
class Tolerance:
    """How ours must relate to the published value: within `value` (abs, in the number's unit),
    within `value` relative (rel), below / above the bound `value` (a conclusion the thesis
    draws, where its number itself is not reproduced), or at most `value`."""
    kind: str
    value: float

    def ok(self, ours, published):
        pairs = list(zip(_seq(ours), _seq(published)))
        if len(pairs) != len(_seq(published)) or any(o is None or math.isnan(o) for o, _ in pairs):
            return False
        if self.kind == "abs":
            return all(abs(o - p) <= self.value * (1 + 1e-9) for o, p in pairs)
        if self.kind == "rel":
            return all(abs(o - p) <= self.value * abs(p) * (1 + 1e-9) for o, p in pairs)
        if self.kind == "below":
            return all(o < self.value for o, _ in pairs)
        if self.kind == "above":
            return all(o > self.value for o, _ in pairs)
        if self.kind == "at_most":
            return all(o <= self.value for o, _ in pairs)
        raise ValueError(f"unknown tolerance kind {self.kind!r}")

    def text(self):
        return {"abs": f"± {self.value:g}", "rel": f"± {100 * self.value:g} %", "below": f"< {self.value:g}",
                "above": f"> {self.value:g}", "at_most": f"<= {self.value:g}"}[self.kind]


@dataclass(frozen=True)
class Number:
    key: str
    quantity: str
    source: str
    published: object  # float or tuple of floats
    unit: str
    tolerance: Tolerance
    test: str  # path::function of the test that calls assert_reproduces(key, ...)
    digits: int = 3
    note: str = ""


def _seq(x):
    return tuple(x) if isinstance(x, (tuple, list)) else (x,)


T_SYSTEMS = "tests/systems/test_systems.py::test_euler_cosimulation_reproduces_thesis"
T_TOTALS = "tests/systems/test_systems.py::test_euler_durations_and_slew_case3_totals"
T_MISSION = "tests/systems/test_mission_system.py"
T_STUDY = "tests/systems/test_deorbit_system.py::test_thesis_compliance_conclusions_with_jacchia_roberts"
T_LIBRARY = "tests/components/orbit/test_propulsion.py::test_deorbit_scenarios_match_thesis"
T_WORST = "tests/systems/test_propulsion_report.py::test_worst_case_budget_reproduces_section_339"


def _thesis_case_numbers():
    out = []
    for name in ("detumble_case1", "detumble_case2", "slew_case1", "slew_case2", "slew_case3_x", "slew_case3_y",
                 "slew_case3_z"):
        t = thesis.THESIS[name]
        eq = t["source"].split(",")[0]
        label = name.replace("_case", " case ").replace("_", " ")
        five = name in ("slew_case1", "slew_case2")
        # half a unit of the last printed decimal; z's q1 is printed 0.1460 where we get 0.14593
        q_tol = 1e-4 if name == "slew_case3_z" else (0.5e-5 if five else 0.5e-4)
        out += [
            Number(f"{name}.q", f"{label}: final quaternion", eq, t["q"], "", Tolerance("abs", q_tol), T_SYSTEMS,
                   5 if five else 4, "q1 printed 0.1460, ours 0.14593" if name == "slew_case3_z" else ""),
            Number(f"{name}.omega", f"{label}: final rate", eq, t["omega"], "deg/s", Tolerance("abs", 0.5e-4),
                   T_SYSTEMS, 4),
            Number(f"{name}.euler", f"{label}: final Eq. 31 angles", eq, t["euler"], "deg", Tolerance("abs", 0.005),
                   T_SYSTEMS, 2, "body rates integrated (dynamics.euler_integrated), not the attitude's angles"),
            Number(f"{name}.duration", f"{label}: duration", eq, t["duration"], "s", Tolerance("abs", 0.015),
                   T_SYSTEMS, 3, "one 15 ms step; the detumble script's clock stops a step early"
                   if name.startswith("detumble") else ""),
        ]
        if t["propellant"] is not None:
            out.append(Number(f"{name}.propellant", f"{label}: propellant", "section 3.3.9", t["propellant"], "g",
                              Tolerance("abs", 0.005), T_SYSTEMS, 3))
    out += [Number("slew_case3.duration", "slew case 3: total duration", "section 3.3.7", 166.26, "s",
                   Tolerance("abs", 0.015), T_TOTALS, 3),
            Number("slew_case3.propellant", "slew case 3: propellant (worst-case slew)", "section 3.3.9", 16.03, "g",
                   Tolerance("abs", 0.005), T_TOTALS, 3)]
    return out


def _mission_numbers():
    m = lambda name: f"{T_MISSION}::{name}"  # noqa: E731
    ref = mission.THESIS[DEFAULT_SCENARIO]  # the scenario the thesis sizes its budgets for
    phases, battery, data = (m("test_attitude_phases_reproduce_the_thesis"), m("test_battery_through_the_deorbit"),
                             m("test_data_storage_and_downlink"))
    return [
        Number("mission_420km.detumble_time_s", "mission 420 km: detumble", "section 3.3.5", ref["detumble_time_s"],
               "s", Tolerance("abs", 0.015), phases, 3),
        Number("mission_420km.slew_time_s", "mission 420 km: slew", "section 3.3.6", ref["slew_time_s"], "s",
               Tolerance("abs", 0.015), phases, 3),
        Number("mission_420km.burn_time_min", "mission 420 km: burn", "section 3.2, 3.3.8", ref["burn_time_min"],
               "min", Tolerance("rel", 0.005), phases, 2),
        Number("mission_420km.tracking_propellant_g", "mission 420 km: attitude control during the burn",
               "section 3.3.9", ref["tracking_propellant_g"], "g", Tolerance("rel", 0.25), phases,
               3, "15 ms limit cycle of Eq. 72; its count of pulses is sensitive to the step"),
        Number("mission_420km.soc_after_burn_percent", "mission 420 km: battery after the burn", "section 3.5, Fig. 46",
               ref["soc_after_burn_percent"], "%", Tolerance("abs", 1.0), battery, 2,
               "the final contact lasts 637 s here; Appendix I's maneuver time is 176.23 s, ours 34.8 s"),
        Number("mission_420km.energy_used_Wh", "mission 420 km: energy used to the end of the burn", "section 3.5",
               ref["energy_used_Wh"], "Wh", Tolerance("abs", 0.15), battery, 3),
        Number("mission_420km.energy_left_Wh", "mission 420 km: energy left after the burn", "section 3.5",
               ref["energy_left_Wh"], "Wh", Tolerance("abs", 0.15), battery, 3),
        Number("mission_420km.battery_empty_days_after_burn", "mission 420 km: battery empty after the burn",
               "section 3.5 (\"about two weeks\")", ref["battery_empty_days_after_burn"], "days", Tolerance("abs", 4.0),
               battery, 1),
        Number("mission_420km.max_storage_MB", "mission 420 km: largest data stored", "section 3.6, Fig. 47",
               ref["max_storage_MB"], "MB", Tolerance("below", 0.1), data, 4, "the thesis: below 0.1 MB"),
        Number("mission_420km.contacts_to_downlink", "mission 420 km: contacts after the burn to downlink",
               "section 3.6", ref["contacts_to_downlink"], "", Tolerance("at_most", 2), data, 0),
    ]


def _deorbit_numbers():
    out = []
    for name, t in deorbit_study.THESIS.items():
        fig = f"section 3.2, Fig. {t['figure']}"
        out += [
            Number(f"deorbit_{name}.delta_v_m_s", f"{name}: delta-V (Eq. 2)", "section 3.2", t["delta_v"], "m/s",
                   Tolerance("abs", 0.005), T_LIBRARY, 2),
            Number(f"deorbit_{name}.propellant_kg", f"{name}: burn propellant (Eq. 3)", "section 3.2", t["propellant"],
                   "kg", Tolerance("abs", 0.0005), T_LIBRARY, 4),
            Number(f"deorbit_{name}.burn_time_min", f"{name}: burn time, simulated", "section 3.2", t["burn_min"],
                   "min",
                   Tolerance("rel", 0.005), T_STUDY, 2),
            Number(f"deorbit_{name}.life_burn_years", f"{name}: lifetime with the burn", fig, t["life_burn"], "years",
                   Tolerance("below", 5.0), T_STUDY, 2,
                   "compliance reproduced, the value is not: today's space weather (see the lifetime comparison)"),
        ]
        compliant = t["life_no_burn"] < 5.0
        out.append(Number(f"deorbit_{name}.life_no_burn_years", f"{name}: lifetime without NEIGHBOR", fig,
                          t["life_no_burn"], "years", Tolerance("below" if compliant else "above", 5.0), T_STUDY, 2,
                          "compliance reproduced" if compliant else
                          "non-compliance reproduced; the suite's runs stop at 5.5 years"))
    return out


T_STAND_IN = "tests/systems/test_deorbit_system.py::test_lifetimes_with_the_thesis_space_weather_stand_in"


def _stand_in_numbers():
    return [Number(f"deorbit_thesis_sw_{name}.life_{kind}_years",
                   f"{name}: lifetime {'with the burn' if kind == 'burn' else 'without NEIGHBOR'}, thesis-era space "
                   "weather", f"section 3.2, Fig. {t['figure']}", t[f"life_{kind}"], "years", Tolerance("rel", 0.10),
                   T_STAND_IN, 2, "`deorbit-study --space-weather thesis`: 130 sfu to 2030, then 75 sfu held")
            for name, t in deorbit_study.THESIS.items() for kind in ("no_burn", "burn")]


def _propulsion_numbers():
    rows = [("rcs_propellant_g", "worst-case attitude-control propellant", "section 3.3.9", "g", 0.05, 3,
             "detumble 1 + slew 3 simulated + tracking of the mission run"),
            ("total_propellant_kg", "worst-case total propellant", "section 3.3.9", "kg", 0.0005, 4, ""),
            ("moles", "tank: propellant amount", "Eq. 75", "mol", 0.005, 3, ""),
            ("volume_cm3", "tank: inner volume", "Eq. 75", "cm3", 0.5, 1, ""),
            ("inner_radius_cm", "tank: inner radius", "Eq. 76", "cm", 0.005, 3, ""),
            ("wall_thickness_cm", "tank: wall thickness", "Eq. 77", "cm", 0.005, 4, ""),
            ("outer_volume_cm3", "tank: outer volume", "Appendix H", "cm3", 0.5, 1, ""),
            ("shell_mass_g", "tank: shell mass", "Appendix H", "g", 0.5, 1, ""),
            ("feed_lines_mass_g", "feed lines: mass", "Table 4", "g", 0.005, 2, ""),
            ("feed_lines_outer_volume_cm3", "feed lines: outer volume", "Table 4", "cm3", 0.005, 2, ""),
            ("assembly_g", "propulsion assembly mass", "section 3.3.9", "g", 1.0, 2,
             "the simulated propellant, 0.3 g above the thesis' 0.587 kg, adds 0.5 g")]
    return [Number(f"propulsion.{key}", label, src, propulsion_report.THESIS[key], unit, Tolerance("abs", tol),
                   T_WORST, digits, note)
            for key, label, src, unit, tol, digits, note in rows]


NUMBERS = (_thesis_case_numbers() + _mission_numbers() + _deorbit_numbers() + _stand_in_numbers()
           + _propulsion_numbers())
BY_KEY = {n.key: n for n in NUMBERS}
if len(BY_KEY) != len(NUMBERS):
    raise RuntimeError("duplicate keys in the validation table")

# key -> test node ids that checked it in this process (read by the suite's coverage check)
CHECKED: Dict[str, Any] = {}


def assert_reproduces(key, ours):
    """The guard a test applies: ours within the table's tolerance of the published value."""
    number = BY_KEY[key]
    CHECKED.setdefault(key, set()).add(os.environ.get("PYTEST_CURRENT_TEST", "").split(" ")[0])
    if not number.tolerance.ok(ours, number.published):
        raise AssertionError(f"{key} ({number.quantity}, {number.source}): ours {ours} vs published "
                             f"{number.published} {number.unit}, tolerance {number.tolerance.text()}")


# ---- computing ours ---------------------------------------------------------------------------
def compute(ssp_dir=DEFAULT_SSP_DIR, progress=False):
    """Run everything the table needs; returns {key: ours}."""
    ours = {}
    cases = thesis.run_cases(ssp_dir, "euler")
    for name, r in cases.items():
        ours[f"{name}.q"], ours[f"{name}.omega"], ours[f"{name}.euler"] = r.q, r.omega_deg, r.euler_deg
        ours[f"{name}.duration"], ours[f"{name}.propellant"] = r.duration, r.propellant
    s, _ = mission.run_mission(DEFAULT_SCENARIO, ssp_dir=ssp_dir, progress=progress, gnc="thesis")
    for key in ("detumble_time_s", "slew_time_s", "burn_time_min", "tracking_propellant_g", "soc_after_burn_percent",
                "energy_used_Wh", "energy_left_Wh", "battery_empty_days_after_burn", "max_storage_MB",
                "contacts_to_downlink"):
        ours[f"mission_420km.{key}"] = s.get(key)
    worst, _ = propulsion_report.worst_case(s, ssp_dir, cases)
    ours.update({f"propulsion.{k}": v for k, v in worst.items()})
    study = deorbit_study.run_study("averaged", "jacchia_roberts", ssp_dir=ssp_dir, progress=progress)
    for name in deorbit_study.THESIS:
        b, n = study[name], study[name + "_no_burn"]
        ours[f"deorbit_{name}.delta_v_m_s"] = abs(b["delta_v_m_s"])
        ours[f"deorbit_{name}.propellant_kg"] = b["propellant_kg"]
        ours[f"deorbit_{name}.burn_time_min"] = b["burn_time_min"]
        ours[f"deorbit_{name}.life_burn_years"] = b["lifetime_years"] if b["reentered"] else None
        ours[f"deorbit_{name}.life_no_burn_years"] = n["lifetime_years"] if n["reentered"] else math.inf
    study = deorbit_study.run_study("averaged", "jacchia_roberts", ssp_dir=ssp_dir, space_weather_file="thesis",
                                    progress=progress)
    for run, s in study.items():
        kind = "no_burn" if run.endswith("_no_burn") else "burn"
        ours[f"deorbit_thesis_sw_{s['scenario']}.life_{kind}_years"] = s["lifetime_years"] if s["reentered"] else None
    return {k: v for k, v in ours.items() if k in BY_KEY}


# ---- the table --------------------------------------------------------------------------------
def _fmt(value, digits):
    if value is None:
        return "-"
    if isinstance(value, (tuple, list)):
        return "[" + ", ".join(_fmt(v, digits) for v in value) + "]"
    if math.isinf(value):
        return "no re-entry"
    return f"{value:.{digits}f}"


def difference(number, ours):
    """Relative difference in % for a number; for a vector (whose printed components can be
    0.0003) the largest absolute difference, in the number's unit."""
    if ours is None:
        return "-"
    pairs = [(o, p) for o, p in zip(_seq(ours), _seq(number.published)) if math.isfinite(o)]
    if isinstance(number.published, tuple):
        return f"max {max(abs(o - p) for o, p in pairs):.1e}" + (f" {number.unit}" if number.unit else "")
    if not pairs or not pairs[0][1]:
        return "-"
    return f"{100.0 * (pairs[0][0] - pairs[0][1]) / pairs[0][1]:+.2f} %"


def table(ours):
    lines = ["| quantity | source | published | ours | difference | tolerance | holds | guarded by |",
             "|---|---|---|---|---|---|---|---|"]
    for n in NUMBERS:
        value = ours.get(n.key)
        unit = f" {n.unit}" if n.unit else ""
        holds = "yes" if n.tolerance.ok(value, n.published) else "NO"
        published = _fmt(n.published, n.digits) if not isinstance(n.published, int) else str(n.published)
        quantity = n.quantity + (f" ({n.note})" if n.note else "")
        lines.append(f"| {quantity} | {n.source} | {published}{unit} | {_fmt(value, n.digits)}{unit} | "
                     f"{difference(n, value)} | {n.tolerance.text()}{'' if n.tolerance.kind == 'rel' else unit} | "
                     f"{holds} | `{n.test.split('::')[-1]}` |")
    return "\n".join(lines) + "\n"


BEGIN = "<!-- generated by `neighbor-cosim validation --markdown docs/validation.md`: do not edit below -->"
END = "<!-- end of generated table -->"


def write_markdown(path, ours):
    """Replace the generated block of `path` (between BEGIN and END) with the table."""
    path = Path(path)
    text = path.read_text() if path.is_file() else ""
    block = f"{BEGIN}\n\n{table(ours)}\n{END}"
    if BEGIN in text and END in text:
        text = re.sub(re.escape(BEGIN) + ".*?" + re.escape(END), lambda _: block, text, flags=re.S)
    else:
        text = text.rstrip("\n") + ("\n\n" if text else "") + block + "\n"
    write_text_atomic(path, text)


def main(argv=None):
    ap = ArgumentParser(prog="neighbor-cosim validation", description=__doc__.split("\n\n")[0])
    ap.add_argument("--ssp-dir", default=str(DEFAULT_SSP_DIR),
                    help="folder of the built systems (default: %(default)s)")
    ap.add_argument("--markdown", metavar="FILE", help="rewrite the generated table block of this Markdown file")
    ap.add_argument("--json", metavar="FILE", help="also write {key: ours} as JSON")
    add_console_arguments(ap)
    args = ap.parse_args(argv)
    progress = console_settings(args)
    # the places the results go, checked before the two-minute run (they used to fail after it)
    # and before a first build of the systems (minutes on a fresh install)
    if args.markdown:
        check_output_file(args.markdown, "--markdown", (".md", ".markdown"))
        if Path(args.markdown).is_file():
            try:
                Path(args.markdown).read_text(encoding="utf-8")
            except (OSError, UnicodeDecodeError) as exc:
                raise SSPError(f"--markdown {args.markdown}: cannot read it as UTF-8 text ({exc})") from None
    if args.json:
        check_output_file(args.json, "--json", (".json",))
    resolve_system(str(Path(args.ssp_dir) / "detumble.ssp"))  # built first if it is a missing default
    ours = compute(args.ssp_dir, progress)
    print(table(ours), end="")
    if args.markdown:
        write_markdown(args.markdown, ours)
    if args.json:
        write_text_atomic(Path(args.json), json.dumps(ours, indent=1, default=list))
    failed = [n.key for n in NUMBERS if not n.tolerance.ok(ours.get(n.key), n.published)]
    if failed:
        print(f"{len(failed)} number(s) outside their tolerance: {', '.join(failed)}", file=sys.stderr)
        return 1
    print(f"all {len(NUMBERS)} published numbers within their tolerances")
    return 0


if __name__ == "__main__":
    sys.exit(main())
