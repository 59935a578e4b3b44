"""System specs (system_ssp.ssp.spec, `neighbor-cosim compose`): a spec of our FMUs and a
third-party one equals the same system written by hand as SSD; `compose --from` gives, for the
shipped systems and for systems other tools wrote, a spec that composes back to a system with the
same results; bad specs are refused in one line naming the file, the line and the key."""
import re
import shutil
import zipfile

import fmpy
import numpy as np
import pytest

from master_fixtures import helpers as h
from paths import DATA
import system_ssp
import system_ssp.systems
from system_ssp import cli
from system_ssp.errors import SSPError
from system_ssp.locations import FMU_DIR
from system_ssp.tools.compose import compose_system, spec_from_system
from system_ssp.tools.export_fmu import export_fmu
from test_ssp_shapes import as_ssp2, balls, nested_system, top_level_connectors_system

FEEDTHROUGH = DATA / "reference_fmus" / "2.0" / "Feedthrough.fmu"

# Six of our FMUs and the Modelica Reference FMU Feedthrough standing in for a user's flight
# computer: it reads the gyro's x rate in deg/s and commands an x torque (in its own units: uN.m).
SPEC = """\
[system]
name = "sun_knowledge"
description = "A tumbling CubeSat's Sun sensor and gyro, with our own flight computer"

[master]
step_size = 0.1
stop_time = 30.0

[components.orbit]
fmu = "CircularOrbit"
[components.sun]
fmu = "SunEphemeris"
[components.shadow]
fmu = "EarthShadow"
[components.dynamics]
fmu = "RigidBody"
parameter_files = ["spacecraft"]
parameters = { omega0 = [0.05, -0.02, 0.01], integrator = "rk4" }
[components.sun_sensor]
fmu = "SunSensor"
parameters = { seed = 7, half_fov = 1.2 }
[components.gyro]
fmu = "Gyro"
[components.computer]
fmu = "FMU_PATH"

[connections]
links = [
  "shadow.orbit_day -> sun_sensor.sunlit",
  { from = "gyro.omega_meas_B[1]", to = "computer.Float64_continuous_input", from_unit = "rad/s", to_unit = "deg/s" },
  { from = "computer.Float64_continuous_output", to = "dynamics.torque_B[1]", factor = -1e-6 },
]
"""

# The same system as a tool's user writes it by hand: components without connector lists, the
# values in one parameter set bound to the system.
HAND_SSD = """<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon" version="1.0" name="by_hand">
  <ssd:System name="by_hand">
    <ssd:ParameterBindings><ssd:ParameterBinding source="values.ssv"/></ssd:ParameterBindings>
    <ssd:Elements>
      <ssd:Component name="orbit" source="resources/CircularOrbit.fmu"/>
      <ssd:Component name="sun" source="resources/SunEphemeris.fmu"/>
      <ssd:Component name="shadow" source="resources/EarthShadow.fmu"/>
      <ssd:Component name="dynamics" source="resources/RigidBody.fmu">
        <ssd:ParameterBindings><ssd:ParameterBinding source="spacecraft.ssv"/></ssd:ParameterBindings>
      </ssd:Component>
      <ssd:Component name="sun_sensor" source="resources/SunSensor.fmu"/>
      <ssd:Component name="gyro" source="resources/Gyro.fmu"/>
      <ssd:Component name="computer" source="resources/Feedthrough.fmu"/>
    </ssd:Elements>
    <ssd:Connections>
CONNECTIONS
    </ssd:Connections>
  </ssd:System>
  <ssd:DefaultExperiment startTime="0" stopTime="30"/>
</ssd:SystemStructureDescription>
"""
HAND_LINKS = ([("shadow", "orbit_day", "sun_sensor", "sunlit", "")]
              + [("orbit", "r_BN_N[%d]" % i, "shadow", "r_BN_N[%d]" % i, "") for i in (1, 2, 3)]
              + [("sun", "r_SN_N[%d]" % i, c, "r_SN_N[%d]" % i, "") for c in ("shadow", "sun_sensor")
                 for i in (1, 2, 3)]
              + [("orbit", "r_BN_N[%d]" % i, "sun_sensor", "r_BN_N[%d]" % i, "") for i in (1, 2, 3)]
              + [("dynamics", "q_BN[%d]" % i, "sun_sensor", "q_BN[%d]" % i, "") for i in (1, 2, 3, 4)]
              + [("dynamics", "omega_BN_B[%d]" % i, "gyro", "omega_BN_B[%d]" % i, "") for i in (1, 2, 3)]
              + [("gyro", "omega_meas_B[1]", "computer", "Float64_continuous_input",
                  '<ssc:LinearTransformation factor="57.29577951308232" offset="0"/>'),
                 ("computer", "Float64_continuous_output", "dynamics", "torque_B[1]",
                  '<ssc:LinearTransformation factor="-1e-6" offset="0"/>')])
HAND_VALUES = [("dynamics.omega0[1]", "Real", "0.05", None), ("dynamics.omega0[2]", "Real", "-0.02", None),
               ("dynamics.omega0[3]", "Real", "0.01", None), ("dynamics.integrator", "String", "rk4", None),
               ("sun_sensor.seed", "Integer", "7", None), ("sun_sensor.half_fov", "Real", "1.2", None)]


def write_spec(folder, text=SPEC):
    folder.mkdir(parents=True, exist_ok=True)
    shutil.copy(FEEDTHROUGH, folder / "Feedthrough.fmu")
    path = folder / "system.toml"
    path.write_text(text.replace("FMU_PATH", "Feedthrough.fmu"))
    return path


def hand_written(folder):
    (folder / "resources").mkdir(parents=True)
    for name in ("CircularOrbit", "SunEphemeris", "EarthShadow", "RigidBody", "SunSensor", "Gyro"):
        shutil.copy(FMU_DIR / f"{name}.fmu", folder / "resources")
    shutil.copy(FEEDTHROUGH, folder / "resources")
    shutil.copy(system_ssp.systems.PARAMETERS_DIR / "spacecraft.ssv", folder)
    (folder / "values.ssv").write_text(h.ssv_text(HAND_VALUES))
    rows = []
    for a, x, b, y, transform in HAND_LINKS:
        head = f'      <ssd:Connection startElement="{a}" startConnector="{x}" endElement="{b}" endConnector="{y}"'
        rows.append(f"{head}>{transform}</ssd:Connection>" if transform else head + "/>")
    (folder / "SystemStructure.ssd").write_text(HAND_SSD.replace("CONNECTIONS", "\n".join(rows)))
    return folder / "SystemStructure.ssd"


def assert_same_results(a, b):
    assert sorted(a.names) == sorted(b.names)
    assert a.stop_time == b.stop_time and a.steps == b.steps
    for name in a.names:
        np.testing.assert_array_equal(a.data[name], b.data[name], err_msg=name)


def test_a_spec_of_our_fmus_and_a_third_party_one_equals_the_system_written_by_hand(tmp_path, capsys):
    spec = write_spec(tmp_path / "spec")
    assert len(spec.read_text().splitlines()) <= 32
    out = tmp_path / "composed.ssp"
    assert cli.main(["compose", str(spec), "--out", str(out)]) == 0
    report = capsys.readouterr().out
    assert "wired by name:" in report and "  orbit.r_BN_N[1..3] -> shadow.r_BN_N[1..3]" in report
    assert "  dynamics.q_BN[1..4] -> sun_sensor.q_BN[1..4]" in report
    assert "dynamics.torque_B[2] = 0.0 N.m" in report  # unconnected, at its start value
    assert "sun_sensor.sun_B[1..3]" in report  # an output that feeds nothing
    composed = system_ssp.simulate(out)
    by_hand = system_ssp.simulate(hand_written(tmp_path / "hand"), step_size=0.1)
    assert_same_results(composed, by_hand)
    # the loop is closed: the computer's torque turned the body away from its free tumble
    assert composed.final["computer.Float64_continuous_input"] != 0.0
    assert composed.final["dynamics.omega_BN_B[1]"] != pytest.approx(0.05, abs=1e-9)


def test_what_a_spec_records_is_what_a_run_records(tmp_path):
    spec = write_spec(tmp_path / "spec", SPEC.replace("stop_time = 30.0", 'stop_time = 1.0\nrecord = '
                                                      '["dynamics.omega_BN_B", "sun_sensor.valid"]'))
    compose_system(spec, tmp_path / "s.ssp")
    r = system_ssp.simulate(tmp_path / "s.ssp")
    assert r.names == ["dynamics.omega_BN_B[1]", "dynamics.omega_BN_B[2]", "dynamics.omega_BN_B[3]",
                       "sun_sensor.valid"]
    assert len(system_ssp.simulate(tmp_path / "s.ssp", outputs=["gyro.omega_meas_B[1]"]).names) == 1


def roundtrip(source, folder, given="", **run):
    """Spec of `source` (with the lines `given` added to its [master], as a user fills in what
    the system does not say), composed back; both run with `run`; returns the spec's text."""
    folder.mkdir(parents=True, exist_ok=True)
    text = spec_from_system(source, folder / "from.toml")
    if given:
        (folder / "from.toml").write_text(text.replace("[master]\n", f"[master]\n{given}\n"))
    compose_system(folder / "from.toml", folder / "back.ssp")
    assert_same_results(system_ssp.simulate(source, **run), system_ssp.simulate(folder / "back.ssp", **run))
    return text


@pytest.mark.parametrize("name, run", [
    ("detumble", {}), ("slew", {"stop_time": 30.0}), ("sunline", {"stop_time": 20.0}),
    ("sun_avoidance_slew", {"stop_time": 5.0}), ("sun_eclipse", {"stop_time": 600.0}),
    ("attitude_determination", {"stop_time": 5.0}), ("air_bearing", {"stop_time": 5.0}),
    ("acs_modes", {"stop_time": 5.0}), ("deorbit", {"stop_time": 3600.0}), ("deorbit_lifetime", {"stop_time": 3600.0}),
    ("atmosphere", {"stop_time": 600.0}), ("neighbor_mission", {"stop_time": 3 * 86400.0}),
    ("neighbor_mission_lifetime", {"stop_time": 3 * 86400.0})])
def test_compose_from_a_shipped_system_composes_back_to_the_same_results(name, run, tmp_path):
    text = roundtrip(name, tmp_path, **run)
    assert "_files/" not in text  # shipped FMUs by name, not copied
    if name == "neighbor_mission":
        assert "[system_parameters.spacecraft_mass]" in text and 'name = "idle"' in text


@pytest.fixture(scope="module")
def fixture_fmus(tmp_path_factory):
    return h.build_fixture_fmus(tmp_path_factory.mktemp("compose_fmus"))


def test_compose_from_systems_other_tools_wrote(fixture_fmus, tmp_path):
    # libcosim's knuckle-boom crane (its step only in OSP's annotation)
    text = roundtrip(DATA / "libcosim" / "demo.ssp", tmp_path / "crane", stop_time=0.05)
    assert "step_size = 0.0001" in text and 'algorithm = "jacobi"' in text
    # two Reference-FMU BouncingBalls with a bound start value
    (tmp_path / "balls").mkdir()
    ssd = balls(tmp_path / "balls", files={})
    roundtrip(ssd, tmp_path / "balls_spec", step_size=0.01, stop_time=1.0,
              parameters={"bb1.h": 2.0})
    # OMSimulator's shape: root input and parameter connectors bound by a parameter set
    one = top_level_connectors_system(tmp_path / "top", fixture_fmus)
    fill = "step_size = 0.5\nstop_time = 2.0"  # the system gives neither
    text = roundtrip(one, tmp_path / "top_spec", fill, step_size=0.5, stop_time=2.0)
    assert "# step_size = ...  (the system has none: give one)" in text
    assert "[system_parameters.k_cref]" in text
    # the same in SSP 2.0
    two = tmp_path / "two"
    shutil.copytree(one.parent, two)
    for name in ("SystemStructure.ssd", "root.ssv"):
        (two / name).write_text(as_ssp2((two / name).read_text()))
    roundtrip(two / "SystemStructure.ssd", tmp_path / "two_spec", fill, step_size=0.5, stop_time=2.0)
    # a system nested two deep: flattened under the master's dotted names
    text = roundtrip(nested_system(tmp_path / "nested", fixture_fmus, "3"), tmp_path / "nested_spec",
                     "step_size = 0.1\nstop_time = 0.3", step_size=0.1, stop_time=0.3)
    assert '[components."sub.deeper.g2"]' in text


def test_a_spec_can_ask_for_ssp_2(tmp_path):
    spec = write_spec(tmp_path / "spec", SPEC.replace('[system]\n', '[system]\nssp_version = "2.0"\n'))
    compose_system(spec, tmp_path / "two.ssp")
    with zipfile.ZipFile(tmp_path / "two.ssp") as z:
        assert 'version="2.0"' in z.read("SystemStructure.ssd").decode()
    assert system_ssp.simulate(tmp_path / "two.ssp", stop_time=1.0).steps == 10


@pytest.mark.parametrize("change, message", [
    (('fmu = "Gyro"', 'fmu = "Gyr"'), r"system.toml:23: components.gyro.fmu: 'Gyr': no shipped FMU of that name "
                                      r"\(did you mean 'Gyro'"),
    (("[master]\n", "[master]\nstep = 1\n"), r"system.toml:\d+: master.step: unknown key \(did you mean 'step_size'"),
    (("shadow.orbit_day -> sun_sensor.sunlit", "shadow.orbit_dy -> sun_sensor.sunlit"),
     r"system.toml:29: connections.links\[1\]: 'shadow.orbit_dy': EarthShadow has no output 'orbit_dy' "
     r"\(did you mean 'orbit_day'"),
    (("seed = 7", "seed = 7.5"), r"system.toml:21: components.sun_sensor.parameters.seed: 7.5: seed is Integer"),
    (("omega0 = [0.05, -0.02, 0.01]", "omega0 = [0.05, -0.02]"),
     r"system.toml:18: components.dynamics.parameters.omega0: omega0 has 3 element\(s\), the spec gives 2"),
    (('parameter_files = ["spacecraft"]', 'parameter_files = ["spacecraf"]'),
     r"system.toml:17: components.dynamics.parameter_files: 'spacecraf': no shipped parameter set of that name "
     r"\(did you mean 'spacecraft'"),
    (("[connections]\n", "[connections]\nexclude = []\n[extra]\n"), r"system.toml:\d+: unknown table or key 'extra'"),
    (("stop_time = 30.0\n", ""), r"system.toml:\d+: \[master\] needs stop_time"),
    (('to_unit = "deg/s"', 'to_unit = "deg/sec"'),
     r"system.toml:30: connections.links\[2\].to_unit: 'deg/sec': unknown unit \(did you mean 'deg/s'"),
    (('to_unit = "deg/s"', 'to_unit = "m"'),
     r"system.toml:30: connections.links\[2\]: rad/s \(s\^-1\*rad\) cannot be converted to m \(m\)"),
])
def test_a_bad_spec_is_refused_in_one_line_and_nothing_is_written(tmp_path, capsys, change, message):
    spec = write_spec(tmp_path, SPEC.replace(*change))
    assert change[0] in SPEC
    out = tmp_path / "out.ssp"
    assert cli.main(["compose", str(spec), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1, err
    assert re.search(message, err), err
    assert not out.exists()


def test_a_bad_parameter_file_is_named_by_the_path_the_spec_gave(tmp_path, capsys):
    (tmp_path / "mine.ssv").write_text(h.ssv_text([("seed", "Integer", "7", None)]).replace('value="7"', 'valu="7"'))
    spec = write_spec(tmp_path, SPEC.replace('[components.gyro]\nfmu = "Gyro"',
                                             '[components.gyro]\nfmu = "Gyro"\nparameter_files = ["mine.ssv"]'))
    assert cli.main(["compose", str(spec), "--out", str(tmp_path / "out.ssp")]) == 2
    err = capsys.readouterr().err
    assert f"the composed system does not load: {tmp_path / 'mine.ssv'}:" in err and "neighbor_compose_" not in err
    assert not (tmp_path / "out.ssp").exists()


def test_an_ambiguous_name_is_refused_and_exclude_resolves_it(tmp_path):
    text = SPEC.replace("[components.computer]", '[components.sun2]\nfmu = "SunEphemeris"\n[components.computer]')
    spec = write_spec(tmp_path / "a", text)
    with pytest.raises(SSPError, match=r"system.toml:\d+: shadow.r_SN_N\[1\]: several outputs of that name could "
                                       r"feed it \(sun.r_SN_N\[1\], sun2.r_SN_N\[1\]\)"):
        compose_system(spec, tmp_path / "a.ssp")
    assert not (tmp_path / "a.ssp").exists()
    spec = write_spec(tmp_path / "b", text.replace("[connections]\n", '[connections]\nexclude = ["sun2.*"]\n'))
    report = compose_system(spec, tmp_path / "b.ssp").report()
    assert "  sun2.r_SN_N[1..3]" in report.split("outputs that feed nothing")[1]


NESTED = """\
[system]
name = "detumble_with_gyro"
description = "The shipped detumble as a sub-system, and a gyro on its rigid body"

[master]
step_size = 0.015
stop_time = 20.0
stop_when = ["maneuver.detumble.done"]

[components.maneuver]
system = "detumble"
parameters = { "dynamics.omega0" = [0.1, -0.05, 0.08], "detumble.omega_tol" = [0.002, 0.002, 0.002] }

[components.gyro]
fmu = "Gyro"
"""


def test_a_shipped_system_nested_as_a_sub_system(tmp_path):
    spec = tmp_path / "outer.toml"
    spec.write_text(NESTED)
    report = compose_system(spec, tmp_path / "outer.ssp").report()
    # the sub-system's own wiring, under its components' dotted names, and ours to the gyro; what
    # the detumble's spec excludes (its controller's q_BN) stays unconnected here too
    assert "  maneuver.thrusters.torque_B[1..3] -> maneuver.dynamics.torque_B[1..3]" in report
    assert "  maneuver.dynamics.omega_BN_B[1..3] -> gyro.omega_BN_B[1..3]" in report
    assert "maneuver.detumble.q_BN[1] = 0.0" in report
    nested = system_ssp.simulate(tmp_path / "outer.ssp")
    alone = system_ssp.simulate("detumble", parameters={
        **{f"dynamics.omega0[{k}]": w for k, w in enumerate([0.1, -0.05, 0.08], 1)},
        **{f"detumble.omega_tol[{k}]": 0.002 for k in (1, 2, 3)}})
    assert alone.stop_reason.startswith("stop condition detumble.done")
    assert nested.stop_time == alone.stop_time and nested.stop_reason.replace("maneuver.", "") == alone.stop_reason
    for name in alone.names:
        np.testing.assert_array_equal(nested.data[f"maneuver.{name}"], alone.data[name], err_msg=name)
    np.testing.assert_array_equal(nested.data["gyro.omega_BN_B[2]"], alone.data["dynamics.omega_BN_B[2]"])
    # a spec that contains itself, and an unknown shipped system, are refused by line
    spec.write_text(NESTED.replace('system = "detumble"', 'system = "outer.toml"'))
    with pytest.raises(SSPError, match=r"outer.toml:11: components.maneuver.system: 'outer.toml': the system "
                                       r"contains itself"):
        compose_system(spec, tmp_path / "x.ssp")
    spec.write_text(NESTED.replace('system = "detumble"', 'system = "detumbel"'))
    with pytest.raises(SSPError, match=r"outer.toml:11: components.maneuver.system: 'detumbel': no shipped system "
                                       r"of that name \(did you mean 'detumble'"):
        compose_system(spec, tmp_path / "x.ssp")


def test_a_spec_that_extends_another_names_the_file_a_bad_key_came_from(tmp_path):
    base = write_spec(tmp_path, SPEC.replace('fmu = "Gyro"', 'fmu = "Gyr"'))
    child = tmp_path / "child.toml"
    child.write_text(f'extends = "{base.name}"\n\n[system]\nname = "child"\n\n'
                     '[components.orbit]\nfmu = "CircularOrbit"\n')
    with pytest.raises(SSPError, match=r"system.toml:23: components.gyro.fmu: 'Gyr'"):
        compose_system(child, tmp_path / "c.ssp")
    base.write_text(SPEC.replace("FMU_PATH", "Feedthrough.fmu"))
    child.write_text(child.read_text().replace('"CircularOrbit"', '"CircularOrbt"'))
    with pytest.raises(SSPError, match=r"child.toml:7: components.orbit.fmu: 'CircularOrbt'"):
        compose_system(child, tmp_path / "c.ssp")
    child.write_text(child.read_text().replace('"CircularOrbt"', '"CircularOrbit"'))
    assert compose_system(child, tmp_path / "c.ssp").name == "child"


def test_a_composed_system_with_dotted_names_exports_as_one_fmu(tmp_path):
    spec = tmp_path / "outer.toml"
    spec.write_text(NESTED)
    compose_system(spec, tmp_path / "outer.ssp")
    export_fmu(tmp_path / "outer.ssp", tmp_path / "outer.fmu")
    r = fmpy.simulate_fmu(str(tmp_path / "outer.fmu"), stop_time=3.0, output_interval=0.015)
    ours = system_ssp.simulate(tmp_path / "outer.ssp", stop_time=3.0)
    for name in ("maneuver.dynamics.omega_BN_B[1]", "gyro.omega_meas_B[2]"):  # stepped after the controller
        np.testing.assert_array_equal(r[name][:-1], ours.data[name][:-1], err_msg=name)
