"""The mission off the thesis' nominal point in its three scenarios: the first runs of
examples/campaigns/mission_dispersion_<scenario>.toml (closed-loop guidance and control on the
attitude estimator, tumble up to 15 deg/s per axis in either sense, mass 10-14 kg, inertia within
10 % of the box the flight software assumes, thrusters misaligned up to 1 deg and off by up to 5 %
in force, gyro bias and sensor noise with seeds of their own, one fault in a fifth of the runs)
through the campaign runner on Dask: six at 420 km, two at 475 km and two at 525 km (whose burns
are 1.7 and 3 times longer). Every run that has an
attitude finds it, detumbles, slews without a timeout, burns its whole budget within the
scenario's propellant allowances and re-enters within 5 years of the burn; a run with every Sun
sensor dead takes its first fix from the horizon sensor's history and flies the same de-orbit.
bench/bench_dispersion.py runs 100 per scenario."""
import dataclasses
import math
from pathlib import Path

import pytest

from components.core.constants import YEAR
from components.orbit import propulsion
from system_ssp.neighbor import budgets, mission
from system_ssp.tools.campaign import load_spec, run_campaign
from system_ssp.tools.campaign.runner import _read_rows

CAMPAIGNS = Path(__file__).resolve().parents[2] / "examples" / "campaigns"
RUNS = {"420km": 6, "475km": 2, "525km": 2}
# the faults the spec's fault stream gives these runs (one in a fifth of a campaign's runs)
FAULTS = {"420km": ["none"] * 4 + ["thruster_dead", "none"], "475km": ["all_sun_sensors_dead", "none"],
          "525km": ["none", "none"]}


def test_dispersed_missions_deorbit_within_their_budgets(ssp_paths, tmp_path):
    """One test, the scenarios one after another: each campaign takes both cores with its two Dask
    workers, and with pytest-xdist the suite's other tests run on the other pytest worker beside
    it (xdist_group cannot keep three tests on one worker with pytest 9.2: pytest-xdist #1386)."""
    for scenario in RUNS:
        spec = load_spec(CAMPAIGNS / f"mission_dispersion_{scenario}.toml")
        spec = dataclasses.replace(spec, runs=RUNS[scenario], system=ssp_paths["neighbor_mission_lifetime"])
        # the shipped NEIGHBOR requirements (their [values] are the 420 km scenario's limits)
        requirements = mission.REQUIREMENTS if scenario == "420km" else None
        summary = run_campaign(spec, tmp_path / scenario, workers=2, requirements=requirements)
        try:
            _check(scenario, summary, sorted(_read_rows(tmp_path / scenario), key=lambda r: r["run"]))
            if requirements is not None:
                _check_requirements(summary["requirements"], tmp_path / scenario)
        except AssertionError as exc:
            raise AssertionError(f"{scenario}: {exc}") from exc


def _check_requirements(s, out):
    """Six clean runs cannot show 0.99 at 95 %: INCONCLUSIVE, with the runs that would decide it
    (299 in all, the success-run rule); every run stores more than the thesis' 0.1 MB (the closed
    loop's 0.116 MB): FAIL."""
    import xml.etree.ElementTree as ET

    verdicts = {v["id"]: v for v in s["verdicts"]}
    assert {k: (v["verdict"], v["k"], v["n"], v.get("more_runs")) for k, v in verdicts.items()} == {
        "NBR-DEO-1": ("INCONCLUSIVE", 6, 6, 293), "NBR-DEO-2": ("INCONCLUSIVE", 6, 6, 23),
        "NBR-PRO-1": ("INCONCLUSIVE", 6, 6, 293), "NBR-PRO-2": ("INCONCLUSIVE", 6, 6, 53),
        "NBR-DAT-1": ("FAIL", 0, 6, None)}
    assert "about 293 more runs like these would decide it" in verdicts["NBR-DEO-1"]["evidence"]
    assert [u["id"] for u in s["uncovered"]] == ["NBR-PWR-1", "NBR-ACS-1"]  # no campaign metric for them
    suite = ET.parse(out / "requirements.junit.xml").getroot().find("testsuite")
    assert (suite.get("tests"), suite.get("failures"), suite.get("skipped")) == ("5", "1", "4")
    assert "NBR-DAT-1" in (out / "report.html").read_text()


def _check(scenario, summary, rows):
    runs = RUNS[scenario]
    assert [r["run"] for r in rows] == list(range(runs))
    assert [r["error"] for r in rows if r["status"] != "ok"] == []
    assert [r["fault"] for r in rows] == FAULTS[scenario]
    allowance = budgets.allowance(scenario)
    burn_min = propulsion.mission_scenario(scenario)["burn_time"] / 60.0
    if scenario == "420km":
        # the draws cover the range the issue asks for: both senses of tumble, light and heavy
        spins = [math.degrees(r[f"dynamics.omega0[{i}]"]) for r in rows for i in (1, 2, 3)]
        assert min(spins) < -10.0 and max(spins) > 10.0 and max(map(abs, spins)) <= 15.0
        masses = [r["spacecraft_mass"] for r in rows]
        assert min(masses) < 12.0 and max(masses) > 13.0  # lighter and heavier than the nominal 12 kg
        errors = [r[f"thrusters.force_error[{i}]"] for r in rows for i in range(1, 17)]
        assert min(errors) < -0.04 and max(errors) > 0.04 and max(map(abs, errors)) <= 0.05
        # the body's own inertia off the box the flight software assumes, both ways
        inertia = [r[f"dynamics.inertia_error[{i}]"] for r in rows for i in (1, 2, 3)]
        assert min(inertia) < -0.08 and max(inertia) > 0.08 and max(map(abs, inertia)) <= 0.1
        # run 4's x+1 thruster is dead from the start; the rate response names it with x-1: in its
        # fast detumble the x+ command stays on, and "x+1 stuck off" and "x-1 stuck on" then act at
        # the same times, so both valves are closed; below 1 deg/s x-1 is reopened and watched
        # alone, and stays open (components/attitude/thruster_monitor.py): x+1 alone is closed at
        # the end (bit 0), x+2 takes +x. It flies within every check below as the others do
        assert [r["thrusters_disabled"] for r in rows] == [0] * 4 + [0b1, 0]
    # sensor noise on, a noise sequence per run
    assert len({(r["gyro.seed"], r["horizon.seed"], r["sun_sensor.seed"]) for r in rows}) == runs
    for r in rows:
        assert r["reentered"], r
        # no Sun vector from any sensor: the first fix from the horizon sensor's and the gyro's
        # history (components/sensing/nadir_history.py), then the de-orbit as in any other run
        assert r["fixed_without_sun"] == (r["fault"] == "all_sun_sensors_dead"), r
        assert r["budget_spent"], r
        assert r["detumble_timeouts"] == 0 and r["slew_timeouts"] == 0 and r["determination_timeouts"] == 0, r
        # the estimator flew, and well, and its covariance told the truth: NEES near 3, about 5 % of
        # the steps above its 95 % bound. Without the Sun the burn is looser: the body held to the
        # guidance keeps the nadir fixed in its axes, so nothing observes the rotation about the
        # nadir, whose error grows with the gyro bias' error over the burn, and the filter says so,
        # its bias held since the fix (components/sensing/mekf.py) (475 km run 0: 3.3 deg at most
        # in its 69 min burn, the sigma about the nadir, body z, 2.7 deg at its end, the error's RMS
        # 0.8 sigma about that axis and 0.9 about the others; 525 km run 28, outside the suite,
        # drifted to 11 deg at 5 sigma before the bias was held, 5.3 deg at 1.5 sigma now)
        without_sun = r["fault"] == "all_sun_sensors_dead"
        assert 0.0 < r["knowledge_error_max_rad"] < math.radians(8.0 if without_sun else 5.0), r
        assert 2.0 < r["nees_mean"] < 4.0 and r["nees_over_fraction"] < (0.10 if without_sun else 0.08), r
        detumble = r["slew_start_s"] - r["detumble_start_s"]
        slew = r["burn_start_s"] - r["slew_start_s"]
        burn = r["monitoring_start_s"] - r["burn_start_s"]
        assert 0.0 < detumble < 60.0 and 0.0 < slew < 120.0, r
        # the budget at 0.1 N, the same for any mass, less the thrust the off-pulsing gave up (y/z
        # torques from switching axial thrusters off): full-thrust time the same within a step
        assert 0.0 < r["axial_off_s"] < 0.1 * 4 * burn, r
        assert (burn - r["axial_off_s"] / 4.0) / 60.0 == pytest.approx(burn_min, abs=0.1)
        assert r["bias_resets"] == 0 and r["safe_reason"] == 0, r  # no false fault detection
        assert r["burn_propellant_kg"] == pytest.approx(propulsion.mission_scenario(scenario)["propellant"], abs=1e-4)
        # within the scenario's attitude-control allowance (the thesis' sizing rule for its burn,
        # system_ssp/neighbor/budgets.py) and its tank
        assert r["rcs_propellant_kg"] <= allowance.rcs_g / 1e3, r
        assert r["burn_propellant_kg"] + r["rcs_propellant_kg"] <= allowance.tank_kg, r
        # the centre of mass followed the propellant drawn from the tank at the module's centre
        # (x = -0.1 m), to within the 0.1 g the mass properties are recomputed at
        drawn = r["burn_propellant_kg"] + r["rcs_propellant_kg"]
        assert r["com_shift_m"] == pytest.approx(drawn * 0.1 / (r["spacecraft_mass"] - drawn), abs=2e-6), r
        assert (r["end_s"] - r["burn_start_s"]) / YEAR < 5.0, r
    assert summary["probabilities"]["reentered"]["p"] == 1.0
    assert summary["probabilities"]["rcs_within_allowance"]["p"] == 1.0
