"""FMI 3.0 co-simulation FMUs in the master (system_ssp.master.fmi3): the Modelica Reference FMUs
built for FMI 3.0 (tests/data/reference_fmus/3.0, vendored with their licence) equal FMPy's own
FMI 3.0 simulation; every FMI 3.0 type the master transfers crosses from FMI 2.0 to FMI 3.0
components and back; arrays connect element by element (dimensions from structural parameters
too); the product's systems packed with the FMI 3.0 FMUs (build/ssp3) give the FMI 2.0 results
exactly, whole systems and systems mixing the two."""
import shutil

import fmpy
import numpy as np
import pytest

from paths import DATA
import system_ssp
from system_ssp import cli
from system_ssp.ssp.writer import single_fmu_system

FMUS3 = DATA / "reference_fmus" / "3.0"
FMUS2 = DATA / "reference_fmus" / "2.0"
CASES = [("BouncingBall", 3.0, 0.01), ("Dahlquist", 10.0, 0.1), ("VanDerPol", 20.0, 0.01), ("StateSpace", 1.0, 0.1)]


@pytest.mark.parametrize("model, stop, step", CASES)
def test_reference_fmi3_fmu_equals_fmpy(model, stop, step, tmp_path):
    """FMPy's FMI 3.0 simulation at the same communication step, every output at every row; an
    array output (StateSpace's y, sized by the structural parameter r) as its elements y[1]..y[3]."""
    path = FMUS3 / f"{model}.fmu"
    expected = fmpy.simulate_fmu(str(path), stop_time=stop, output_interval=step, fmi_type="CoSimulation")
    result = system_ssp.simulate(single_fmu_system(path, tmp_path), stop_time=stop, step_size=step)
    assert len(result.data) == len(expected)
    np.testing.assert_array_equal(result.data["time"], expected["time"])
    for name in expected.dtype.names[1:]:
        values = expected[name].reshape(len(expected), -1).astype(float)
        columns = [f"{model}.{name}"] if values.shape[1] == 1 else [f"{model}.{name}[{i + 1}]"
                                                                    for i in range(values.shape[1])]
        for k, column in enumerate(columns):
            np.testing.assert_array_equal(result.data[column].astype(float), values[:, k], err_msg=column)


def test_fmi3_stair_ends_the_run_where_it_asks(tmp_path, capsys):
    """FMI 3.0's way to end a simulation (fmi3DoStep's terminateSimulation) ends the run as
    FMI 2.0's does: at 9 s, exit 0."""
    out = tmp_path / "stair.csv"
    code = cli.main(["run", str(FMUS3 / "Stair.fmu"), "--stop-time", "10", "--step-size", "0.2", "--output", str(out)])
    printed = capsys.readouterr()
    assert code == 0, printed.err
    assert "stop time:   9 s (component 'Stair' ended the simulation at t=9 s" in printed.out
    assert out.read_text().splitlines()[-1] == "9.0,10"


def _feedthrough_system(tmp_path, chain):
    """Feedthroughs named a, b, c ... of the FMI versions in `chain`, each output of one into the
    same input of the next (every type the master transfers), VanDerPol and Stair driving the
    first's Float64 and Int32 inputs, Boolean/String/Enumeration bound on the first."""
    from master_fixtures import helpers as h
    (tmp_path / "resources").mkdir()
    shutil.copy(FMUS2 / "VanDerPol.fmu", tmp_path / "resources" / "VanDerPol.fmu")
    shutil.copy(FMUS2 / "Stair.fmu", tmp_path / "resources" / "Stair.fmu")
    for version in set(chain):
        src = (FMUS2 if version == 2 else FMUS3) / "Feedthrough.fmu"
        shutil.copy(src, tmp_path / "resources" / f"Feedthrough{version}.fmu")
    bind = ('<ssd:ParameterBinding><ssd:ParameterValues>'
            + h.ssv_text([("Boolean_input", "Boolean", "true", None),
                          ("String_input", "String", "text, with a comma", None),
                          ("Enumeration_input", "Enumeration", "Option 2", None)]).split("?>", 1)[1]
            + "</ssd:ParameterValues></ssd:ParameterBinding>")
    names = "abcdefgh"[:len(chain)]
    elements = h.component("vdp", "VanDerPol.fmu") + h.component("stair", "Stair.fmu")
    for i, (name, version) in enumerate(zip(names, chain)):
        elements += h.component(name, f"Feedthrough{version}.fmu", bindings=bind if i == 0 else "")
    conns = h.connection("vdp.x0", "a.Float64_continuous_input") + h.connection("stair.counter", "a.Int32_input")
    types = ["Float64_continuous", "Int32", "Boolean", "String", "Enumeration"]
    for x, y in zip(names, names[1:]):
        conns += "".join(h.connection(f"{x}.{t}_output", f"{y}.{t}_input") for t in types)
    (tmp_path / "SystemStructure.ssd").write_text(h.ssd_text(elements, conns))
    return tmp_path / "SystemStructure.ssd", names[-1]


@pytest.mark.parametrize("chain", [(2, 3, 2), (3, 3)], ids=["fmi2-fmi3-fmi2", "fmi3-fmi3"])
def test_every_type_crosses_between_fmi2_and_fmi3_feedthroughs(chain, tmp_path):
    """Float64, Int32, Boolean, String and Enumeration (an FMI 3.0 Int64) through Reference
    Feedthroughs of both versions in one system: the last output equals the source at every row."""
    ssd, last = _feedthrough_system(tmp_path, chain)
    r = system_ssp.simulate(ssd, stop_time=2.0, step_size=0.2)
    np.testing.assert_array_equal(r.data[f"{last}.Float64_continuous_output"], r.data["vdp.x0"])
    np.testing.assert_array_equal(r.data[f"{last}.Int32_output"], r.data["stair.counter"])
    assert np.ptp(r.data["vdp.x0"]) > 0.1 and r.data["stair.counter"][-1] > r.data["stair.counter"][0]
    assert r.data[f"{last}.Boolean_output"].all() and set(r.data[f"{last}.Enumeration_output"]) == {2}
    assert set(r.data[f"{last}.String_output"]) == {"text, with a comma"}


def test_fmi3_only_types_between_fmi3_feedthroughs(tmp_path):
    """Float32, Int8, UInt16 and UInt64 between two FMI 3.0 Feedthroughs (values bound on the
    first, in range of each type), read back at the second."""
    from master_fixtures import helpers as h
    (tmp_path / "resources").mkdir()
    shutil.copy(FMUS3 / "Feedthrough.fmu", tmp_path / "resources" / "Feedthrough.fmu")
    values = [("Float32_discrete_input", "Real", "0.5"), ("Int8_input", "Integer", "-7"),
              ("UInt16_input", "Integer", "60000"), ("UInt64_input", "Integer", "123456")]
    bind = ('<ssd:ParameterBinding><ssd:ParameterValues>'
            + h.ssv_text([(n, t, v, None) for n, t, v in values]).split("?>", 1)[1]
            + "</ssd:ParameterValues></ssd:ParameterBinding>")
    elements = h.component("a", "Feedthrough.fmu", bindings=bind) + h.component("b", "Feedthrough.fmu")
    conns = "".join(h.connection(f"a.{n.replace('_input', '_output')}", f"b.{n}") for n, _, _ in values)
    (tmp_path / "SystemStructure.ssd").write_text(h.ssd_text(elements, conns))
    r = system_ssp.simulate(tmp_path / "SystemStructure.ssd", stop_time=0.4, step_size=0.2)
    for name, _, value in values:
        out = f"b.{name.replace('_input', '_output')}"
        assert r.data[out][-1] == float(value), out


def test_a_binary_connector_is_refused_naming_why(tmp_path):
    from master_fixtures import helpers as h
    (tmp_path / "resources").mkdir()
    shutil.copy(FMUS3 / "Feedthrough.fmu", tmp_path / "resources" / "Feedthrough.fmu")
    elements = h.component("a", "Feedthrough.fmu") + h.component("b", "Feedthrough.fmu")
    (tmp_path / "SystemStructure.ssd").write_text(h.ssd_text(elements, h.connection("a.Binary_output",
                                                                                    "b.Binary_input")))
    with pytest.raises(system_ssp.SSPError, match=r"SystemStructure.ssd:9: connection a.Binary_output -> "
                                                  r"b.Binary_input: component 'a' has no variable 'Binary_output': the "
                                                  r"FMU's variable is a Binary variable, which this master does not "
                                                  r"transfer"):
        system_ssp.System(tmp_path / "SystemStructure.ssd")


def test_statespace_array_input_set_element_by_element(tmp_path):
    """StateSpace (FMI 3.0, A..D sized by structural parameters) with its array input u[1..3]
    driven by three VanDerPol/Dahlquist outputs: y equals FMPy's run of the same FMU with the
    same inputs (y = C x + D u with its start matrices: identity)."""
    from master_fixtures import helpers as h
    (tmp_path / "resources").mkdir()
    shutil.copy(FMUS3 / "StateSpace.fmu", tmp_path / "resources" / "StateSpace.fmu")
    shutil.copy(FMUS3 / "VanDerPol.fmu", tmp_path / "resources" / "VanDerPol.fmu")
    elements = h.component("vdp", "VanDerPol.fmu") + h.component("ss", "StateSpace.fmu")
    conns = h.connection("vdp.x0", "ss.u[1]") + h.connection("vdp.x1", "ss.u[3]")
    (tmp_path / "SystemStructure.ssd").write_text(h.ssd_text(elements, conns))
    r = system_ssp.simulate(tmp_path / "SystemStructure.ssd", stop_time=1.0, step_size=0.1)
    # u[2] keeps its start value (2) while u[1] and u[3] are set: the array is set whole
    assert set(r.data["ss.u[2]"]) == {2.0}
    np.testing.assert_array_equal(r.data["ss.u[1]"], r.data["vdp.x0"])
    np.testing.assert_array_equal(r.data["ss.u[3]"], r.data["vdp.x1"])
    assert np.ptp(r.data["ss.y[1]"]) > 0


def test_thesis_detumble_and_slew_equal_with_fmi3_fmus(ssp_paths, ssp3_paths):
    """The product's systems packed with the FMI 3.0 FMUs: every recorded signal equals the FMI 2.0
    run exactly (the same model code behind both standards)."""
    for name in ("detumble", "slew"):
        r2 = system_ssp.simulate(ssp_paths[name])
        r3 = system_ssp.simulate(ssp3_paths[name])
        assert r2.data.dtype.names == r3.data.dtype.names
        for column in r2.data.dtype.names:
            np.testing.assert_array_equal(r3.data[column], r2.data[column], err_msg=f"{name}: {column}")
        assert r3.final == r2.final


def test_a_system_mixing_fmi2_and_fmi3_components_of_ours(ssp_paths, fmu3_paths, tmp_path):
    """`replace` puts the FMI 3.0 twin of one component into the FMI 2.0 detumble system (the
    interfaces compare equal): the run equals the FMI 2.0 one."""
    out = tmp_path / "mixed.ssp"
    assert cli.main(["replace", str(ssp_paths["detumble"]), "dynamics", str(fmu3_paths["RigidBody"]),
                     "--out", str(out)]) == 0
    r2, r3 = system_ssp.simulate(ssp_paths["detumble"]), system_ssp.simulate(out)
    for column in r2.data.dtype.names:
        np.testing.assert_array_equal(r3.data[column], r2.data[column], err_msg=column)


def _whole_array_system(tmp_path, fmu_paths, fmu3_paths, conns):
    from master_fixtures import helpers as h
    (tmp_path / "resources").mkdir()
    shutil.copy(fmu3_paths["RigidBody"], tmp_path / "resources" / "RigidBody3.fmu")
    shutil.copy(fmu3_paths["AttitudeToDcm"], tmp_path / "resources" / "AttitudeToDcm3.fmu")
    shutil.copy(fmu_paths["AttitudeToDcm"], tmp_path / "resources" / "AttitudeToDcm2.fmu")
    bind = ('<ssd:ParameterBinding><ssd:ParameterValues>'
            + h.ssv_text([("omega0[1]", "Real", "0.1", None), ("omega0[3]", "Real", "-0.05", None)]).split("?>", 1)[1]
            + "</ssd:ParameterValues></ssd:ParameterBinding>")
    elements = (h.component("dynamics", "RigidBody3.fmu", bindings=bind) + h.component("dcm3", "AttitudeToDcm3.fmu")
                + h.component("dcm2", "AttitudeToDcm2.fmu"))
    (tmp_path / "SystemStructure.ssd").write_text(h.ssd_text(elements, "".join(h.connection(a, b) for a, b in conns)))
    return tmp_path / "SystemStructure.ssd"


def test_arrays_connected_whole(fmu_paths, fmu3_paths, tmp_path):
    """`dynamics.q_BN -> dcm3.q_BN` between FMI 3.0 arrays, and to the FMI 2.0 twin's q_BN[1] ..
    q_BN[4], named without indices: one connection per element; both DCMs equal."""
    ssd = _whole_array_system(tmp_path, fmu_paths, fmu3_paths,
                              [("dynamics.q_BN", "dcm3.q_BN"), ("dynamics.q_BN", "dcm2.q_BN")])
    r = system_ssp.simulate(ssd, stop_time=1.0, step_size=0.1)
    for k in range(1, 5):
        np.testing.assert_array_equal(r.data[f"dcm2.q_BN[{k}]"], r.data[f"dynamics.q_BN[{k}]"])
    assert np.ptp(r.data["dynamics.q_BN[1]"]) > 0.01
    for i in range(1, 4):
        for j in range(1, 4):
            np.testing.assert_array_equal(r.data[f"dcm3.dcm_BN[{i},{j}]"], r.data[f"dcm2.dcm_BN[{i},{j}]"])


def test_whole_arrays_of_different_sizes_are_refused(fmu_paths, fmu3_paths, tmp_path):
    ssd = _whole_array_system(tmp_path, fmu_paths, fmu3_paths, [("dynamics.omega_BN_B", "dcm3.q_BN")])
    with pytest.raises(system_ssp.SSPError, match=r"SystemStructure.ssd:\d+: connection dynamics.omega_BN_B -> "
                                                  r"dcm3.q_BN: arrays of 3 and 4 elements"):
        system_ssp.System(ssd)
