"""FMI 1.0 co-simulation FMUs in the master (system_ssp.master.fmi1): the Modelica Reference FMUs
built as FMI 1.0 (tests/data/reference_fmus/1.0) equal FMPy's own FMI 1.0 simulation bit for
bit; libcosim's FMI 1.0 test system (tests/data/libcosim/ssp/linear_transformation, with the
ViProMa identity FMU) and a coupled FMI 1.0 system equal libcosim's runs of the same files; every
type travels through FMI 1.0 FMUs beside FMI 2.0 ones."""
import shutil
import zipfile

import fmpy
import numpy as np
import pytest

from master_fixtures import helpers as h
from paths import DATA
import system_ssp
from system_ssp import cli
from system_ssp.ssp.writer import single_fmu_system

FMI1 = DATA / "reference_fmus" / "1.0"
FMI2 = DATA / "reference_fmus" / "2.0"
LINEAR = DATA / "libcosim" / "ssp" / "linear_transformation"
CASES = [("BouncingBall", 3.0, 0.01), ("Dahlquist", 10.0, 0.1), ("VanDerPol", 20.0, 0.01), ("Stair", 10.0, 0.2),
         ("Feedthrough", 2.0, 0.1)]


@pytest.mark.parametrize("model, stop, step", CASES)
def test_reference_fmu_as_fmi1_equals_fmpy(model, stop, step, tmp_path):
    path = FMI1 / f"{model}.fmu"
    assert fmpy.read_model_description(str(path)).fmiVersion == "1.0"
    expected = fmpy.simulate_fmu(str(path), stop_time=stop, output_interval=step, fmi_type="CoSimulation")
    result = system_ssp.simulate(single_fmu_system(path, tmp_path), stop_time=stop, step_size=step)
    np.testing.assert_array_equal(result.data["time"], expected["time"])
    for name in expected.dtype.names[1:]:
        np.testing.assert_array_equal(result.data[f"{model}.{name}"].astype(float), expected[name].astype(float),
                                      err_msg=name)


def test_an_fmi1_fmu_runs_from_the_command_line_with_a_parameter(tmp_path, capsys):
    """Dahlquist (x' = -k x) as FMI 1.0: its parameter k set before fmiInitializeSlave; the
    last value by hand: x(1) = (1 - k h)^n with its forward Euler step of 0.1 s."""
    out = tmp_path / "d.csv"
    code = cli.main(["run", str(FMI1 / "Dahlquist.fmu"), "--stop-time", "1", "--step-size", "0.1", "--set",
                     "Dahlquist.k=2", "--output", str(out)])
    printed = capsys.readouterr()
    assert code == 0, printed.err
    assert float(out.read_text().splitlines()[-1].split(",")[1]) == pytest.approx((1 - 2 * 0.1) ** 10, rel=1e-12)


def test_every_type_through_fmi1_and_fmi2_feedthroughs(tmp_path):
    """Real, Integer, Boolean and Enumeration from FMI 2.0 sources through an FMI 1.0
    Feedthrough into an FMI 2.0 one (fmiBoolean is a char: converted both ways): every output of
    the last equals its source at every row."""
    (tmp_path / "resources").mkdir()
    shutil.copy(FMI2 / "VanDerPol.fmu", tmp_path / "resources" / "VanDerPol.fmu")
    shutil.copy(FMI2 / "Stair.fmu", tmp_path / "resources" / "Stair.fmu")
    shutil.copy(FMI2 / "Feedthrough.fmu", tmp_path / "resources" / "Feedthrough2.fmu")
    shutil.copy(FMI1 / "Feedthrough.fmu", tmp_path / "resources" / "Feedthrough1.fmu")
    bind = ('<ssd:ParameterBinding><ssd:ParameterValues>'
            + h.ssv_text([("Boolean_input", "Boolean", "true", None),
                          ("Enumeration_input", "Enumeration", "Option 2", None)]).split("?>", 1)[1]
            + "</ssd:ParameterValues></ssd:ParameterBinding>")
    types = ("Float64_continuous", "Int32", "Boolean", "Enumeration")
    elements = (h.component("vdp", "VanDerPol.fmu") + h.component("stair", "Stair.fmu")
                + h.component("src", "Feedthrough2.fmu", bindings=bind) + h.component("old", "Feedthrough1.fmu")
                + h.component("new", "Feedthrough2.fmu"))
    conns = h.connection("vdp.x0", "old.Float64_continuous_input") + h.connection("stair.counter", "old.Int32_input")
    conns += h.connection("src.Boolean_output", "old.Boolean_input")
    conns += h.connection("src.Enumeration_output", "old.Enumeration_input")
    conns += "".join(h.connection(f"old.{t}_output", f"new.{t}_input") for t in types)
    (tmp_path / "SystemStructure.ssd").write_text(h.ssd_text(elements, conns))
    with system_ssp.System(tmp_path / "SystemStructure.ssd") as system:
        r = system.run(stop_time=2.0, step_size=0.2)
        assert any("'old'" in w and "no output dependencies" in w for w in system.warnings)
    np.testing.assert_array_equal(r.data["new.Float64_continuous_output"], r.data["vdp.x0"])
    np.testing.assert_array_equal(r.data["new.Int32_output"], r.data["stair.counter"])
    assert np.ptp(r.data["vdp.x0"]) > 0.1 and r.data["stair.counter"][-1] > r.data["stair.counter"][0]
    assert r.data["new.Boolean_output"].all() and set(r.data["new.Enumeration_output"]) == {2}
    assert r.order == ["vdp", "stair", "src", "old", "new"]  # old's outputs taken to depend on its inputs


def test_libcosims_linear_transformation_system(tmp_path):
    """libcosim's own FMI 1.0 test system, unchanged: identity1.realIn is bound twice (2, then 4).
    SSP 1.0 applies both in order, the later winning: realOut = 4, identity2.realIn = 1.3 * 4 + 50.
    libcosim applies only a component's first binding (its default parameter set): with realIn set
    to 2 here too, the two masters agree to the last bit at every step."""
    r = system_ssp.simulate(LINEAR, stop_time=0.005, step_size=1e-3)
    assert set(r.data["identity1.realOut"]) == {4.0}
    assert set(r.data["identity2.realIn"]) == {1.3 * 4.0 + 50.0} and set(r.data["identity2.realOut"]) == {55.2}
    names = ["identity1.realOut", "identity2.realIn", "identity2.realOut"]
    n = 20
    pytest.importorskip("libcosimpy")  # what is checked above needs only this master
    ref = h.libcosim_rows(LINEAR, 1e-3, n, names, tmp_path)
    ours = system_ssp.simulate(LINEAR, stop_time=n * 1e-3, step_size=1e-3, algorithm="jacobi",
                               parameters={"identity1.realIn": 2.0})
    np.testing.assert_array_equal(np.column_stack([ours.data[name][1:] for name in names]), ref)
    assert ref[-1].tolist() == [2.0, 1.3 * 2.0 + 50.0, 1.3 * 2.0 + 50.0]


def test_the_identity_fmu_passes_every_type(tmp_path):
    """The ViProMa identity FMU's Integer, Boolean and String outputs (value reference 0 of each
    type, aliases of its inputs) follow its inputs; its inputs are set before fmiInitializeSlave."""
    r = system_ssp.simulate(LINEAR, stop_time=0.003, step_size=1e-3, parameters={
        "identity1.integerIn": 7, "identity1.booleanIn": True, "identity1.stringIn": "a b, c"})
    assert set(r.data["identity1.integerOut"]) == {7}
    assert r.data["identity1.booleanOut"].all()
    assert set(r.data["identity1.stringOut"]) == {"a b, c"}


def test_a_coupled_fmi1_system_equals_libcosim(tmp_path):
    """VanDerPol's x0 through two FMI 1.0 Feedthroughs, the second's output scaled by a
    LinearTransformation into the third, as libcosim's Jacobi-type algorithm steps it."""
    pytest.importorskip("libcosimpy")
    (tmp_path / "resources").mkdir()
    for m in ("VanDerPol", "Feedthrough"):
        shutil.copy(FMI1 / f"{m}.fmu", tmp_path / "resources" / f"{m}.fmu")
    def real(name, kind):  # libcosim connects declared connectors only
        return f'<ssd:Connector name="{name}" kind="{kind}"><ssc:Real/></ssd:Connector>'

    feedthrough = real("Float64_continuous_input", "input") + real("Float64_continuous_output", "output")
    elements = (h.component("vdp", "VanDerPol.fmu", real("x0", "output"))
                + h.component("a", "Feedthrough.fmu", feedthrough) + h.component("b", "Feedthrough.fmu", feedthrough))
    conns = (h.connection("vdp.x0", "a.Float64_continuous_input")
             + h.connection("a.Float64_continuous_output", "b.Float64_continuous_input",
                            '<ssc:LinearTransformation factor="-2" offset="0.5"/>'))
    (tmp_path / "SystemStructure.ssd").write_text(h.ssd_text(elements, conns))
    names = ["vdp.x0", "a.Float64_continuous_output", "b.Float64_continuous_output"]
    step, n = 0.01, 100
    ref = h.libcosim_rows(tmp_path, step, n, names, tmp_path)
    r = system_ssp.simulate(tmp_path / "SystemStructure.ssd", stop_time=n * step, step_size=step, algorithm="jacobi")
    ours = np.column_stack([r.data[name][1:] for name in names])
    np.testing.assert_allclose(ours, ref, rtol=0, atol=1e-12)
    assert np.ptp(ref[:, 2]) > 0.1


def test_an_fmi1_model_exchange_fmu_is_refused(tmp_path, capsys):
    """FMI 1.0 model exchange (no co-simulation interface) is refused in one line, alone and as a
    component of a system."""
    bad = tmp_path / "DahlquistME.fmu"
    with zipfile.ZipFile(FMI1 / "Dahlquist.fmu") as zin, zipfile.ZipFile(bad, "w") as zout:
        for item in zin.infolist():
            data = zin.read(item.filename)
            if item.filename == "modelDescription.xml":
                text = data.decode()
                start, end = text.index("<Implementation>"), text.index("</Implementation>") + len("</Implementation>")
                data = (text[:start] + text[end:]).encode()
            zout.writestr(item, data)
    assert cli.main(["run", str(bad), "--stop-time", "1", "--step-size", "0.1"]) == 2
    err = capsys.readouterr().err.strip()
    assert err == f"error: {bad}: has no co-simulation interface (model exchange only), which the master needs"
    (tmp_path / "resources").mkdir()
    shutil.copy(bad, tmp_path / "resources" / "DahlquistME.fmu")
    (tmp_path / "SystemStructure.ssd").write_text(h.ssd_text(h.component("d", "DahlquistME.fmu")))
    with pytest.raises(system_ssp.SSPError, match=r"component 'd': .*DahlquistME.fmu is an FMI 1.0 model-exchange "
                                                  r"FMU; this master runs co-simulation FMUs"):
        system_ssp.System(tmp_path / "SystemStructure.ssd")


def test_an_fmi1_fmu_under_an_nc_schedule(tmp_path):
    """FMPy reads an FMI 1.0 FMU's canHandleVariableCommunicationStepSize as False; the master
    reads its Capabilities (true for the Reference FMUs), so the FMU runs under nc:Schedule: one
    unconditional mode of 0.2 s equals the fixed-step run of 0.2 s."""
    (tmp_path / "resources").mkdir()
    shutil.copy(FMI1 / "VanDerPol.fmu", tmp_path / "resources" / "VanDerPol.fmu")
    schedule = ('<ssd:Annotations><ssc:Annotation type="org.neighbor-cosim.master"><nc:Master '
                'xmlns:nc="https://neighbor-cosim.org/ssp/master" stepSize="0.2"><nc:Schedule>'
                '<nc:Mode name="all" stepSize="0.2"/>'
                '</nc:Schedule></nc:Master></ssc:Annotation></ssd:Annotations>')
    ssd = tmp_path / "SystemStructure.ssd"
    ssd.write_text(h.ssd_text(h.component("vdp", "VanDerPol.fmu"), system_extra=schedule))
    scheduled = system_ssp.simulate(ssd, stop_time=2.0)
    fixed = system_ssp.simulate(ssd, stop_time=2.0, step_size=0.2, schedule=False)
    assert scheduled.modes["all"]["steps"] == 10
    np.testing.assert_array_equal(scheduled.data["vdp.x0"], fixed.data["vdp.x0"])
