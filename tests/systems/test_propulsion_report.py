"""The propulsion report from simulated maneuvers, the validation table (every published number,
its tolerance and its guard) and the thesis column of every scenario's mission summary."""
import ast
import json
import re

import pytest

from paths import REPO
from system_ssp import cli
from system_ssp.neighbor import mission, propulsion_report, validation
from system_ssp.neighbor.validation import assert_reproduces


def test_worst_case_budget_reproduces_section_339(thesis_cases, mission_420km):
    """Section 3.3.9 sized from simulated maneuvers: detumble case 1 and slew case 3 through the
    master, the tracking and the burn of the 420 km mission run; then Eq. 75-79 and Table 4."""
    s, _, _ = mission_420km
    worst, cases = propulsion_report.worst_case(s, cases=thesis_cases)
    assert cases is thesis_cases  # nothing re-run
    assert worst["slew_propellant_g"] == thesis_cases["slew_case3"].propellant  # simulated, not typed in
    assert worst["detumble_propellant_g"] == thesis_cases["detumble_case1"].propellant
    assert worst["tracking_propellant_g"] == s["tracking_propellant_g"]
    assert worst["burn_propellant_kg"] == s["burn_propellant_kg"]
    for key in ("rcs_propellant_g", "total_propellant_kg", "moles", "volume_cm3", "inner_radius_cm",
                "wall_thickness_cm", "outer_volume_cm3", "shell_mass_g", "feed_lines_mass_g",
                "feed_lines_outer_volume_cm3", "assembly_g"):
        assert_reproduces(f"propulsion.{key}", worst[key])
    # the run's own budget is smaller: it slews like case 1
    own = propulsion_report.of_mission(s)
    assert own["total_propellant_kg"] < worst["total_propellant_kg"] - 0.011
    assert own["assembly_g"] < worst["assembly_g"]
    text = propulsion_report.report(worst, own, "420km")
    assert "| tank inner volume (cm3, Eq. 75) | 376." in text and "| 376.4 |" in text


def test_propulsion_command_reads_a_mission_summary(mission_420km, ssp_paths, tmp_path, capsys):
    _, _, out = mission_420km
    code = cli.main(["propulsion", "--mission", str(out / "summary.json"), "--ssp-dir", str(ssp_paths["slew"].parent),
                     "--json", str(tmp_path / "p.json")])
    assert code == 0
    printed = capsys.readouterr().out
    assert "propulsion assembly (g)" in printed and "2086.93" in printed
    saved = json.loads((tmp_path / "p.json").read_text())
    assert saved["worst_case"]["slew_propellant_g"] == pytest.approx(16.03, abs=0.005)
    # the budgets against the tank and the RCS allowance, and Tables 8-9 (tests/systems/test_budgets.py)
    assert "budgets, worst case:" in printed and "budgets, this mission:" in printed
    assert "| attitude-control (RCS) propellant (g) |" in printed and "Mass and volume, 420km scenario" in printed
    assert "| 2652.13 |" in printed and "| 1271.84 |" in printed
    assert saved["mass_g"]["thesis"]["total"] == pytest.approx(2652.13)
    worst = {b["name"]: b for b in saved["budgets"]["worst_case"]}
    assert worst["attitude-control (RCS) propellant"]["allowed"] == pytest.approx(23.14)
    assert worst["total propellant"]["used"] == saved["worst_case"]["total_propellant_kg"]
    # a summary of another scenario is refused, naming both
    assert cli.main(["propulsion", "--scenario", "475km", "--mission", str(out / "summary.json")]) == 2
    assert "'420km' mission run, not --scenario 475km" in capsys.readouterr().err


def test_every_scenario_summary_carries_the_thesis_column(mission_420km):
    s, _, _ = mission_420km
    assert s["thesis"]["burn_time_min"] == 38.74 and s["altitude_at_deorbit_kind"] == "mean"
    assert "| burn time (min) | 38.7" in mission.table(s) and " % |" in mission.table(s)
    for scenario, burn, propellant, life in (("475km", 67.42, 0.982, 3.44), ("525km", 117.20, 1.707, 3.19)):
        ref = mission.THESIS[scenario]
        assert (ref["burn_time_min"], ref["burn_propellant_kg"], ref["lifetime_with_burn_years"]) == (burn, propellant,
                                                                                                       life)
        # the same run's numbers printed against another scenario's column: every published row shows
        text = mission.table({**s, "scenario": scenario, "thesis": ref})
        assert f"| {burn} |" in text and f"| {propellant} |" in text and f"| {life} |" in text
        assert f"{scenario} scenario" in text


def _function_source(test):
    path, name = test.split("::")
    tree = ast.parse((REPO / path).read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef) and node.name == name:
            return ast.get_source_segment((REPO / path).read_text(), node)
    return None


def test_every_published_number_names_a_test_that_checks_it():
    """Each row's guard exists and calls assert_reproduces (that it checked the row's key in a
    full run is checked at the end of the session, tests/conftest.py)."""
    for number in validation.NUMBERS:
        source = _function_source(number.test)
        assert source is not None, f"{number.key}: {number.test} does not exist"
        assert "assert_reproduces" in source, f"{number.key}: {number.test} does not call assert_reproduces"
        assert number.tolerance.ok(number.published, number.published) or number.tolerance.kind in ("below", "above")


def test_docs_validation_table_is_the_generated_one():
    """docs/validation.md's generated block lists every row of the table, in order, with the
    published value, tolerance and guard of the registry, and each of its 'ours' holds."""
    text = (REPO / "docs" / "validation.md").read_text()
    assert validation.BEGIN in text and validation.END in text
    block = text.split(validation.BEGIN)[1].split(validation.END)[0]
    rows = [line for line in block.splitlines() if line.startswith("| ") and not line.startswith("| quantity")]
    assert len(rows) == len(validation.NUMBERS)
    for row, number in zip(rows, validation.NUMBERS):
        cells = [c.strip() for c in row.strip("|").split("|")]
        assert cells[1] == number.source and cells[-1] == f"`{number.test.split('::')[-1]}`", row
        assert cells[5].startswith(number.tolerance.text()) and cells[6] == "yes", row


def test_tolerance_kinds():
    t = validation.Tolerance
    assert t("abs", 0.01).ok((1.0, 2.005), (1.0, 2.0)) and not t("abs", 0.01).ok((1.0, 2.02), (1.0, 2.0))
    assert t("rel", 0.1).ok(1.09, 1.0) and not t("rel", 0.1).ok(1.2, 1.0)
    assert t("below", 5).ok(4.9, 2.2) and not t("below", 5).ok(float("inf"), 2.2)
    assert t("above", 5).ok(float("inf"), 25.0) and t("at_most", 2).ok(2, 2) and not t("at_most", 2).ok(3, 2)
    assert not t("abs", 1.0).ok(None, 1.0) and not t("abs", 1.0).ok((1.0,), (1.0, 2.0))
    with pytest.raises(AssertionError, match=re.escape("slew_case1.duration (slew case 1: duration, Eq. 47)")):
        assert_reproduces("slew_case1.duration", 30.0)
