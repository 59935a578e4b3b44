"""The de-orbit systems through the master: the burn, the fidelity swap,
the thesis' compliance conclusions and bad input."""
import math

import numpy as np
import pytest

from browser import open_page

from components.orbit import propulsion
import system_ssp
from system_ssp import SimulationError, SSPError
from system_ssp.neighbor import deorbit_study
from system_ssp.neighbor.validation import assert_reproduces
from system_ssp.systems import PARAMETERS_DIR

PARAMS = PARAMETERS_DIR


@pytest.fixture(scope="module")
def lifetime_system(ssp_paths):
    with system_ssp.System(ssp_paths["deorbit_lifetime"]) as s:
        yield s


def test_burn_through_the_master(lifetime_system):
    """420 km: the Propulsion FMU burns the Eq. 2-3 budget in 38.74 min (0.5 s steps while
    burning), the orbit's mean perigee drops by about the Eq. 2 amount."""
    r = lifetime_system.run(stop_time=3 * 3600.0, parameter_sets=[str(PARAMS / "deorbit_420km.ssv")],
                            outputs=["propulsion.burning", "orbit.perigee_altitude", "orbit.apogee_altitude"])
    ref = propulsion.deorbit_scenario(420e3, 350e3)
    assert r.final["propulsion.propellant_used"] == pytest.approx(ref["propellant"], rel=1e-9)
    assert r.final["propulsion.burn_time"] / 60.0 == pytest.approx(38.74, rel=0.005)
    assert r.modes["burn"]["simulated_time"] == pytest.approx(ref["burn_time"], abs=0.5)
    assert r.final["orbit.mass"] == pytest.approx(12.0 - ref["propellant"], rel=1e-9)
    # a finite 39 min burn is not the impulsive Eq. 2 transfer: perigee near 360 km, not 350
    assert 345e3 < r.final["orbit.perigee_altitude"] < 370e3
    assert 400e3 < r.final["orbit.apogee_altitude"] < 420e3


def test_cowell_and_averaged_agree_on_the_burn(ssp_paths, lifetime_system):
    """The fidelity swap: the same scenario files on both systems. The burn lowers the mean
    semi-major axis by the same amount in both (burn minus no-burn run, 3 h after the start;
    Cowell's osculating a averaged over the last orbit, sampled every 10 s)."""
    def drop(system, mean_of_last_orbit):
        a = {}
        for ssv in ("deorbit_420km.ssv", "deorbit_420km_no_burn.ssv"):
            r = system.run(stop_time=3 * 3600.0, parameter_sets=[str(PARAMS / ssv)], outputs=["orbit.sma"],
                           schedule=not mean_of_last_orbit, step_size=10.0)
            last = r.data["time"] > r.data["time"][-1] - 5570.0
            a[ssv] = np.mean(r.data["orbit.sma"][last]) if mean_of_last_orbit else r.final["orbit.sma"]
        return a["deorbit_420km_no_burn.ssv"] - a["deorbit_420km.ssv"]

    with system_ssp.System(ssp_paths["deorbit"]) as cowell:
        cowell_drop = drop(cowell, True)
    averaged_drop = drop(lifetime_system, False)
    assert 30e3 < averaged_drop < 40e3
    assert cowell_drop == pytest.approx(averaged_drop, rel=0.02)


def test_thesis_compliance_conclusions_with_jacchia_roberts(tmp_path):
    """Hard requirement: every burn case re-enters within 5 years, the 475 and 525 km hosts
    without NEIGHBOR take longer (runs capped at 5.5 years)."""
    summary = deorbit_study.run_study("averaged", "jacchia_roberts", max_years=5.5, out=tmp_path)
    for name in deorbit_study.THESIS:
        assert summary[name]["reentered"] and summary[name]["lifetime_years"] < 5.0, summary[name]
    for name in ("475km", "525km"):
        assert not summary[name + "_no_burn"]["reentered"], summary[name + "_no_burn"]
    assert summary["420km_no_burn"]["reentered"]
    for name in deorbit_study.THESIS:  # the validation table's entries for the study
        burn, no_burn = summary[name], summary[name + "_no_burn"]
        assert_reproduces(f"deorbit_{name}.burn_time_min", burn["burn_time_min"])
        assert_reproduces(f"deorbit_{name}.life_burn_years", burn["lifetime_years"])
        assert_reproduces(f"deorbit_{name}.life_no_burn_years",
                          no_burn["lifetime_years"] if no_burn["reentered"] else math.inf)
    for name in deorbit_study.THESIS:
        assert (tmp_path / f"altitude_{name}.png").stat().st_size > 10000
    assert "| 420km | 19.84 (19.84) | 0.564 (0.564) | 38.74 (38.74) |" in (tmp_path / "table.md").read_text()
    assert "(4.38; " in (tmp_path / "table.md").read_text()  # the relative difference beside the thesis' value
    dom, console = open_page(tmp_path / "report.html")  # the study's report, drawn by a real browser
    assert console == [] and dom.count('class="main-svg"') >= 6 and "420km: orbital lifetime" in dom


def test_lifetimes_with_the_thesis_space_weather_stand_in(tmp_path):
    """The lifetime comparison (docs/models/orbit.md): with the bundled file the lifetimes are
    11-47 % shorter than the thesis'; with the stand-in for the thesis' file (history to 2023,
    130 sfu to 2030, 75 sfu held after) all six come within 10 %. The solar activity explains
    the difference; the full study (up to 91 years) takes about 25 s with the averaged orbit."""
    summary = deorbit_study.run_study("averaged", "jacchia_roberts", space_weather_file="thesis", out=tmp_path)
    for run, s in summary.items():
        assert s["reentered"] and s["space_weather"] == deorbit_study.THESIS_SPACE_WEATHER_FILE, run
        kind = "no_burn" if run.endswith("_no_burn") else "burn"
        assert_reproduces(f"deorbit_thesis_sw_{s['scenario']}.life_{kind}_years", s["lifetime_years"])
    assert (tmp_path / deorbit_study.THESIS_SPACE_WEATHER_FILE).is_file()  # kept with the results
    assert "thesis.txt space weather" in (tmp_path / "table.md").read_text()


@pytest.mark.parametrize("params, pattern", [
    ({"orbit.sma0": 6378136.3 + 240e3}, "reentry_altitude"),
    ({"orbit.area": -0.02}, "area"),
    ({"orbit.density_model": "jacchia"}, "jacchia"),
    ({"orbit.space_weather_file": "/nonexistent/sw.txt"}, "sw.txt"),
    ({"orbit.epoch": "1990-01-01T00:00:00Z"}, "1990"),
    ({"propulsion.mass0": -1.0}, "mass0"),
])
def test_bad_input_names_the_problem(lifetime_system, params, pattern):
    with pytest.raises(SimulationError, match=pattern):
        lifetime_system.run(stop_time=60.0, parameters=params)


def test_study_arguments():
    with pytest.raises(SSPError, match="unknown scenario"):
        deorbit_study.run_study(scenarios=["600km"])
    with pytest.raises(SSPError, match="unknown model"):
        deorbit_study.run_study(model="sgp4")
    assert math.isclose(deorbit_study.THESIS["525km"]["life_no_burn"], 97.41)


def test_a_mispointed_burn_costs_delta_v_through_the_fmus(fmu_paths, tmp_path):
    """Guidance -> orbit coupling through the master: the orbit thrusts along the body's thrust
    axis at the attitude the BurnGuidance FMU computes from the orbit. A thrust axis 20 deg off
    the body x axis (propulsion.axis_B) lowers the orbit by cos 20 deg of the aligned burn; the
    aligned burn equals the retrograde (-v) one."""
    from system_ssp.ssp.writer import SystemWriter

    (tmp_path / "resources").mkdir()
    for name in ("BurnGuidance", "OrbitAveraged", "Propulsion"):
        (tmp_path / "resources" / f"{name}.fmu").symlink_to(fmu_paths[name])
    writer = SystemWriter(tmp_path, fmu_paths["Propulsion"].parent)
    writer.ssd("guided_burn", {
        "description": "burn attitude from the orbit, thrust along the body axis",
        "components": [("guidance", "BurnGuidance", []), ("orbit", "OrbitAveraged", []),
                       ("propulsion", "Propulsion", [])],
        "connections": [("orbit", "r_BN_N", "guidance", "r_BN_N", 3), ("orbit", "v_BN_N", "guidance", "v_BN_N", 3),
                        ("guidance", "q_target_BN", "orbit", "q_BN", 4),
                        ("propulsion", "F_thrust_B", "orbit", "F_thrust_B", 3),
                        ("propulsion", "mass", "orbit", "mass", 0)],
        "order": ["propulsion", "orbit", "guidance"], "stop_time": 600.0, "step_size": 0.5})
    drops = {}
    with system_ssp.System(tmp_path / "guided_burn.ssd") as s:
        for label, extra in (("aligned", {}), ("retrograde", {"orbit.retrograde": True}),
                             ("20 deg", {"propulsion.axis_B[1]": math.cos(math.radians(20.0)),
                                         "propulsion.axis_B[2]": math.sin(math.radians(20.0))})):
            r = s.run(stop_time=600.0, parameters={"orbit.density_model": "exponential", "orbit.Cd": 1e-9,
                                                   "propulsion.burn_enable": True, **extra},
                      outputs=["orbit.sma"])
            drops[label] = r.data["orbit.sma"][0] - r.final["orbit.sma"]
    assert drops["aligned"] == pytest.approx(drops["retrograde"], rel=1e-4)
    assert drops["20 deg"] / drops["aligned"] == pytest.approx(math.cos(math.radians(20.0)), rel=2e-3)
