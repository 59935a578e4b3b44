"""The NEIGHBOR mission is defined once (components.mission.neighbor): the scenarios, the
spacecraft's baseline values, the systems and parameter sets, the GNC sets and the recorded
signals. These tests check that everything else agrees with it: the committed parameter files,
the built FMUs' defaults, the models' defaults and the applications' tables, and that no other
source file types a scenario again."""
import ast
import inspect
import math
from pathlib import Path

import fmpy
from lxml import etree
import pytest

from paths import REPO

from components.attitude import thruster_control, thruster_set, thrusters
from components.core.constants import R_EQ
from components.mission import neighbor
from components.mission.neighbor import GNC_SETS, SCENARIOS, SPACECRAFT, scenario_set
from components.orbit import averaged, cowell, propulsion
from system_ssp.neighbor import deorbit_study, mission, propulsion_report
from system_ssp.ssp import reader
from system_ssp.systems import PARAMETERS_DIR, SYSTEMS_DIR

KM = 1000.0


def ssv(name):
    """{parameter name: value} of system_ssp/systems/parameters/<name>.ssv."""
    root = etree.parse(str(PARAMETERS_DIR / f"{name}.ssv")).getroot()
    return {p.name: p.value for p in reader.parse_ssv(root, reader.FileNamer())}


def starts(fmu_path):
    """{variable name: start value} of a built FMU, as the model description declares them."""
    md = fmpy.read_model_description(str(fmu_path))
    return {v.name: float(v.start) for v in md.modelVariables if v.start is not None and v.type == "Real"}


def test_every_scenario_has_its_systems_parameter_sets():
    for name, s in SCENARIOS.items():
        for system in (*neighbor.DEORBIT_SYSTEMS.values(), *neighbor.MISSION_SYSTEMS.values()):
            assert (PARAMETERS_DIR / f"{scenario_set(system, name)}.ssv").is_file()
        budget = propulsion.deorbit_scenario(s.altitude_km * KM, s.target_perigee_km * KM)["propellant"]
        assert propulsion.mission_scenario(name)["propellant"] == budget
        for system in neighbor.DEORBIT_SYSTEMS.values():
            burn = ssv(scenario_set(system, name))
            assert burn["orbit.sma0"] == pytest.approx(R_EQ + s.altitude_km * KM, abs=1e-6)
            assert burn["propulsion.propellant_budget"] == pytest.approx(budget, rel=1e-12)
            assert burn["propulsion.burn_enable"] is True
            assert ssv(scenario_set(system, name, burn=False))["propulsion.burn_enable"] is False
        for system in neighbor.MISSION_SYSTEMS.values():
            assert ssv(scenario_set(system, name))["propulsion.propellant_budget"] == pytest.approx(budget, rel=1e-12)
        if s.thesis:  # the thesis' numbers are Eq. 2-3 for the scenario
            assert budget == pytest.approx(s.thesis["propellant"], abs=6e-4)
    for system in (*neighbor.DEORBIT_SYSTEMS.values(), *neighbor.MISSION_SYSTEMS.values()):
        assert (SYSTEMS_DIR / f"{system}.ssd").is_file()
    for gnc_set in GNC_SETS.values():
        assert gnc_set is None or (PARAMETERS_DIR / f"{gnc_set}.ssv").is_file()


def test_the_applications_read_the_definition():
    assert mission.SCENARIOS == tuple(SCENARIOS)
    assert set(deorbit_study.THESIS) == {name for name, s in SCENARIOS.items() if s.thesis}
    for name, s in SCENARIOS.items():
        if not s.thesis:
            continue
        ref = deorbit_study.THESIS[name]
        assert (ref["h0"], ref["target"]) == (s.altitude_km, s.target_perigee_km)
        assert {k: ref[k] for k in s.thesis} == dict(s.thesis)
        assert mission.THESIS[name]["burn_time_min"] == s.thesis["burn_min"]
        assert mission.THESIS[name]["burn_propellant_kg"] == s.thesis["propellant"]
    base = SCENARIOS[neighbor.DEFAULT_SCENARIO].thesis
    assert (propulsion_report.THESIS["delta_v_m_s"], propulsion_report.THESIS["burn_propellant_kg"]) == (
        base["delta_v"], base["propellant"])
    assert mission.SYSTEMS is neighbor.MISSION_SYSTEMS and deorbit_study.SYSTEMS is neighbor.DEORBIT_SYSTEMS
    assert mission.GNC is GNC_SETS
    assert tuple(mission.RECORD) == neighbor.MISSION_RECORD and tuple(deorbit_study.RECORD) == neighbor.DEORBIT_RECORD


def test_the_committed_parameter_files_carry_the_spacecraft():
    sc = ssv("mission_spacecraft")
    assert (sc["spacecraft_mass"], sc["spacecraft_edge_a"], sc["spacecraft_edge_b"], sc["spacecraft_edge_c"]) == (
        SPACECRAFT.mass, *SPACECRAFT.edges)
    assert (sc["spacecraft_Cd"], sc["spacecraft_drag_area"], sc["rcs_thrust"]) == (
        SPACECRAFT.Cd, SPACECRAFT.drag_area, SPACECRAFT.rcs_thrust)
    for orbit_set in ("deorbit_orbit", "mission_orbit"):
        o = ssv(orbit_set)
        assert (o["Cd"], o["area"]) == (SPACECRAFT.Cd, SPACECRAFT.drag_area)
        assert o["inc0"] == pytest.approx(neighbor.ORBIT.inclination, abs=1e-15)
        assert o["reentry_altitude"] == neighbor.ORBIT.reentry_altitude_km * KM
    p = ssv("deorbit_propulsion")
    assert (p["thrust_per_thruster"], p["n_thrusters"], p["isp"], p["g0"], p["mass0"]) == (
        SPACECRAFT.deorbit_thrust_per_thruster, SPACECRAFT.n_deorbit_thrusters, SPACECRAFT.isp, SPACECRAFT.g0,
        SPACECRAFT.mass)
    assert ssv("mission_propulsion")["mass0"] == SPACECRAFT.mass
    body, rcs = ssv("spacecraft"), ssv("thrusters")
    assert (body["mass"], body["edge_a"], body["edge_b"], body["edge_c"]) == (SPACECRAFT.mass, *SPACECRAFT.edges)
    assert (rcs["thrust"], rcs["edge_a"], rcs["edge_c"], rcs["Isp"], rcs["g0"]) == (
        SPACECRAFT.rcs_thrust, SPACECRAFT.edge_a, SPACECRAFT.edge_c, SPACECRAFT.isp, SPACECRAFT.g0)


def test_the_fmus_defaults_are_the_spacecraft(fmu_paths):
    box = {"mass": SPACECRAFT.mass, "edge_a": SPACECRAFT.edge_a, "edge_b": SPACECRAFT.edge_b,
           "edge_c": SPACECRAFT.edge_c}
    rcs = {"edge_a": SPACECRAFT.edge_a, "edge_c": SPACECRAFT.edge_c, "Isp": SPACECRAFT.isp, "g0": SPACECRAFT.g0}
    expected = {
        "RigidBody": box, "TrackingController": box, "AttitudeEstimator": box, "SunAvoidanceGuidance": box,
        "RcsThrusterSet": {**rcs, "thrust": SPACECRAFT.rcs_thrust}, "RcsThrusters": rcs,
        "Orbit": {"Cd": SPACECRAFT.Cd, "area": SPACECRAFT.drag_area, "mass": SPACECRAFT.mass},
        "OrbitAveraged": {"Cd": SPACECRAFT.Cd, "area": SPACECRAFT.drag_area, "mass": SPACECRAFT.mass},
        "Propulsion": {"thrust_per_thruster": SPACECRAFT.deorbit_thrust_per_thruster, "isp": SPACECRAFT.isp,
                       "g0": SPACECRAFT.g0, "mass0": SPACECRAFT.mass},
    }
    for fmu, values in expected.items():
        declared = starts(fmu_paths[fmu])
        assert {k: declared[k] for k in values} == values, fmu


def test_the_models_defaults_are_the_spacecraft():
    assert (propulsion.MASS0, propulsion.ISP, propulsion.G0, propulsion.THRUST_PER_THRUSTER,
            propulsion.N_THRUSTERS) == (SPACECRAFT.mass, SPACECRAFT.isp, SPACECRAFT.g0,
                                        SPACECRAFT.deorbit_thrust_per_thruster, SPACECRAFT.n_deorbit_thrusters)
    assert thruster_control.F_THRUSTER == SPACECRAFT.rcs_thrust

    def defaults(fn):
        return {k: p.default for k, p in inspect.signature(fn).parameters.items()
                if p.default is not inspect.Parameter.empty}

    for cls in (thrusters.ThrusterPairs, thruster_set.ThrusterSet):
        d = defaults(cls.__init__)
        assert (d["force"], d["a"], d["c"], d["isp"], d["g0"]) == (
            SPACECRAFT.rcs_thrust, SPACECRAFT.edge_a, SPACECRAFT.edge_c, SPACECRAFT.isp, SPACECRAFT.g0), cls
    for cls in (cowell.CowellOrbit, averaged.OrbitAveraged):
        d = defaults(cls.__init__)
        assert (d["Cd"], d["area"]) == (SPACECRAFT.Cd, SPACECRAFT.drag_area), cls
    assert defaults(cowell.CowellOrbit.__init__)["mass"] == SPACECRAFT.mass
    assert thruster_control.pair_torques() == pytest.approx(thruster_control.pair_torques(
        SPACECRAFT.rcs_thrust, SPACECRAFT.edge_a, SPACECRAFT.edge_c))
    assert math.isclose(neighbor.ORBIT.inclination, math.radians(51.6))


def _string_constants(path):
    tree = ast.parse(path.read_text(), str(path))
    return [(node.lineno, node.value) for node in ast.walk(tree)
            if isinstance(node, ast.Constant) and isinstance(node.value, str)]


def test_no_other_source_types_a_scenario():
    """The scenarios' names appear in code only in the mission definition (documentation and
    validation keys may mention them inside longer text)."""
    names = set(SCENARIOS)
    definition = Path(neighbor.__file__).resolve()
    found = []
    for folder in ("components", "fmus", "system_ssp"):
        for path in sorted((REPO / folder).rglob("*.py")):
            if path.resolve() == definition:
                continue
            found += [f"{path.relative_to(REPO)}:{line}: {value!r}" for line, value in _string_constants(path)
                      if value in names]
    assert found == []
