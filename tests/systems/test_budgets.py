"""Budgets: each scenario's allowances from the thesis' sizing rule (section 3.3.9), a run's use
marked within or over in the mission summary, the propulsion report and the dispersion campaign;
Tables 8-9 (section 3.8) from the mission definition and the sized propulsion assembly."""
import json

import pytest

from components.mission.neighbor import DATA_STORAGE_LIMIT_B, PARTS
from paths import REPO
from system_ssp.neighbor import budgets, mission, propulsion_report
from system_ssp.tools.campaign import load_spec

DISPERSION = REPO / "examples" / "campaigns" / "mission_dispersion_420km.toml"


def test_allowance_is_the_thesis_rule_per_scenario():
    a = budgets.allowance("420km")
    # at 420 km the rule gives the thesis' own numbers: 23.14 g of RCS propellant, a 0.587 kg tank
    assert a.rcs_g == pytest.approx(propulsion_report.THESIS["rcs_propellant_g"], abs=1e-9)
    assert a.tank_kg == pytest.approx(propulsion_report.THESIS["total_propellant_kg"], abs=5e-4)
    # the longer burns hold the attitude longer: tracking scales with the burn (67.42, 117.20 min)
    for scenario, burn_min, burn_kg in (("475km", 67.42, 0.982), ("525km", 117.20, 1.707)):
        a = budgets.allowance(scenario)
        assert a.rcs_g == pytest.approx(2.36 + 16.03 + 4.75 * burn_min / 38.74, rel=1e-12)
        assert a.tank_kg == pytest.approx(burn_kg + a.rcs_g / 1e3, rel=1e-12)
        assert f"{burn_min:.2f}/38.74 min" in a.describe()
    assert budgets.allowance("475km").rcs_g == pytest.approx(26.66, abs=0.005)
    assert budgets.allowance("525km").rcs_g == pytest.approx(32.76, abs=0.005)


def _summary(**over):
    s = {"scenario": "420km", "propulsion": propulsion_report.sizing(0.5641, 2.36, 4.51, 4.75),
         "energy_used_Wh": 2.2, "max_storage_MB": 0.0902}
    return {**s, **over}


def test_each_budget_is_marked_within_or_over():
    rows = {b.name: b for b in budgets.of_summary(_summary())}
    assert set(rows) == {"total propellant", "attitude-control (RCS) propellant",
                         "battery energy to the end of the burn", "largest data storage"}
    assert all(b.within for b in rows.values())
    assert rows["largest data storage"].allowed == 0.1 and rows["battery energy to the end of the burn"].allowed == 10.8
    # what the issue measured with the closed loop: 13.5 g of tracking, 0.1163 MB stored
    over = {b.name: b for b in budgets.of_summary(_summary(
        propulsion=propulsion_report.sizing(0.5641, 2.4, 16.03, 13.5), max_storage_MB=0.1163))}
    assert not over["attitude-control (RCS) propellant"].within and not over["total propellant"].within
    assert not over["largest data storage"].within and over["battery energy to the end of the burn"].within
    text = "\n".join(budgets.lines([b.as_dict() for b in over.values()], "budgets:"))
    assert "| largest data storage (MB) | 0.1163 | 0.1 | -16.3 % | OVER |" in text
    assert "| battery energy to the end of the burn (Wh) | 2.2 | 10.8 | +79.6 % | within |" in text
    # a run that never burned has no propellant budget, and says nothing about it
    assert [b.name for b in budgets.of_summary({"scenario": "420km", "max_storage_MB": 0.05})] == [
        "largest data storage"]


def test_mission_summary_carries_its_budgets(mission_420km):
    s, _, out = mission_420km
    saved = json.loads((out / "summary.json").read_text())
    assert saved["budgets"] == s["budgets"] and "RCS allowance 23.14 g" in s["allowance"]
    by_name = {b["name"]: b for b in s["budgets"]}
    rcs = s["detumble_propellant_g"] + s["slew_propellant_g"] + s["tracking_propellant_g"]
    assert by_name["attitude-control (RCS) propellant"]["used"] == pytest.approx(rcs, rel=1e-12)
    assert by_name["total propellant"]["used"] == s["total_propellant_kg"]
    assert by_name["largest data storage"]["used"] == s["max_storage_MB"]
    # the thesis' guidance and control flies inside every allowance
    assert all(b["within"] for b in s["budgets"]), s["budgets"]
    text = mission.table(s)
    assert "budgets, 420km scenario:" in text and "\nRCS allowance 23.14 g = detumble 2.36 g" in text
    assert text.count("| within |") == 4


def test_tables_8_and_9_from_the_mission_definition():
    # as typed in the thesis: its totals
    assert budgets.mass_table()["total"] == pytest.approx(2652.13, abs=1e-6)
    assert budgets.volume_table()["total"] == pytest.approx(1271.84, abs=0.005)
    # the parts' volumes from their dimensions, as Table 9 prints them
    volume = {p.name: p.volume_cm3 for p in PARTS}
    assert volume["horizon sensor"] == pytest.approx(414.0) and volume["UHF antenna"] == pytest.approx(76.39, abs=0.005)
    assert volume["gyroscope"] == pytest.approx(0.00855) and volume["harness"] == 0.0
    # sized from a propellant: the propulsion rows are section 3.3.9's, not the typed ones
    sized = propulsion_report.sizing(0.564, 2.36, 16.03, 4.75)
    mass, vol = budgets.mass_table(sized), budgets.volume_table(sized)
    assert mass["propellant"] == pytest.approx(587.14, abs=1e-9) and mass["propellant tank"] == sized["shell_mass_g"]
    assert vol["propellant tank"] == sized["outer_volume_cm3"] != budgets.THESIS_TANK_VOLUME_CM3
    assert mass["total"] == pytest.approx(2652.13, abs=0.5)  # the thesis rounds the shell and the manifold
    assert vol["total"] == pytest.approx(1271.84 - 627.3 + 488.2, abs=0.2)  # Eq. 76-77's tank, not Table 9's
    heavier = budgets.mass_table(propulsion_report.sizing(1.707, 2.36, 16.03, 14.37))
    assert heavier["total"] > mass["total"] + 1150.0


@pytest.mark.parametrize("scenario", ["420km", "475km", "525km"])
def test_dispersion_campaign_judges_the_same_budgets(scenario):
    """Each scenario's dispersion campaign (475 and 525 km extend the 420 km one) judges the RCS
    propellant against that scenario's allowance and flies that scenario."""
    spec = load_spec(DISPERSION.with_name(f"mission_dispersion_{scenario}.toml"))
    probabilities = {name: (metric, op, threshold) for name, metric, op, threshold in spec.probabilities}
    assert probabilities["rcs_within_allowance"] == ("rcs_propellant_kg", "<=",
                                                    pytest.approx(budgets.allowance(scenario).rcs_g / 1e3, rel=1e-12))
    assert probabilities["storage_within_limit"] == ("max_storage_B", "<=", DATA_STORAGE_LIMIT_B)
    assert spec.parameter_sets == [f"parameters/neighbor_mission_lifetime_{scenario}.ssv"]

