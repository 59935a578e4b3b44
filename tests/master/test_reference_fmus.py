"""FMUs nobody here wrote: Modelica Reference FMUs (FMI 2.0 co-simulation, tests/data/reference_fmus,
vendored with their licence) run in our master as systems of one, equal to FMPy's own
simulate_fmu at the same communication step; Stair ends the simulation the FMI 2.0 way
(fmi2Discard from fmi2DoStep, then fmi2Terminated true), which ends the run cleanly where it says."""
import fmpy
import numpy as np
import pytest

from paths import DATA
import system_ssp
from system_ssp import cli
from system_ssp.ssp.writer import single_fmu_system

FMUS = DATA / "reference_fmus" / "2.0"
# (model, stop time, communication step): the DefaultExperiment where the FMU has one
CASES = [("BouncingBall", 3.0, 0.01), ("Dahlquist", 10.0, 0.1), ("VanDerPol", 20.0, 0.01), ("Resource", 1.0, 0.1),
         ("Stair", 10.0, 0.2)]


@pytest.mark.parametrize("model, stop, step", CASES)
def test_reference_fmu_equals_fmpy(model, stop, step, tmp_path):
    path = FMUS / f"{model}.fmu"
    expected = fmpy.simulate_fmu(str(path), stop_time=stop, output_interval=step, fmi_type="CoSimulation")
    result = system_ssp.simulate(single_fmu_system(path, tmp_path), stop_time=stop, step_size=step)
    assert len(result.data) == len(expected)
    np.testing.assert_array_equal(result.data["time"], expected["time"])
    for name in expected.dtype.names[1:]:
        np.testing.assert_array_equal(result.data[f"{model}.{name}"].astype(float), expected[name].astype(float),
                                      err_msg=name)


def test_stair_ends_the_run_where_it_asks(tmp_path, capsys):
    """Stair's counter reaches 10 at t = 9 s and its fmi2DoStep returns fmi2Discard with
    fmi2Terminated true: the run ends there, exit 0, with the last row at 9 s (before: 'fmi2DoStep
    returned status discard', exit 2)."""
    out = tmp_path / "stair.csv"
    code = cli.main(["run", str(FMUS / "Stair.fmu"), "--stop-time", "10", "--step-size", "0.2", "--output", str(out)])
    printed = capsys.readouterr()
    assert code == 0, printed.err
    assert "stop time:   9 s (component 'Stair' ended the simulation at t=9 s (fmi2Discard, fmi2Terminated))" \
        in printed.out
    assert out.read_text().splitlines()[-2:] == ["8.8,9", "9.0,10"]


def test_every_fmi_type_through_two_reference_feedthroughs(tmp_path, capsys):
    """Real, Integer, Boolean, String and Enumeration, each through a chain of two Reference FMU
    Feedthroughs (outputs equal their inputs): VanDerPol's x0 and Stair's counter move; the
    Boolean, String and Enumeration start from values bound to the first. Every output of the
    second equals its source at every row (checked by hand: the FMUs pass values through)."""
    from master_fixtures import helpers as h
    import shutil
    (tmp_path / "resources").mkdir()
    for m in ("VanDerPol", "Stair", "Feedthrough"):
        shutil.copy(FMUS / f"{m}.fmu", tmp_path / "resources" / f"{m}.fmu")
    types = ("Float64_continuous", "Int32", "Boolean", "String", "Enumeration")
    bind = ('<ssd:ParameterBinding><ssd:ParameterValues>'
            + h.ssv_text([("Boolean_input", "Boolean", "true", None),
                          ("String_input", "String", "a &quot;quoted&quot;, text", None),  # XML-escaped
                          ("Enumeration_input", "Enumeration", "Option 2", None)]).split("?>", 1)[1]
            + "</ssd:ParameterValues></ssd:ParameterBinding>")
    elements = (h.component("vdp", "VanDerPol.fmu") + h.component("stair", "Stair.fmu")
                + h.component("a", "Feedthrough.fmu", bindings=bind) + h.component("b", "Feedthrough.fmu"))
    conns = h.connection("vdp.x0", "a.Float64_continuous_input") + h.connection("stair.counter", "a.Int32_input")
    conns += "".join(h.connection(f"a.{t}_output", f"b.{t}_input") for t in types)
    (tmp_path / "SystemStructure.ssd").write_text(h.ssd_text(elements, conns))
    out = tmp_path / "types.csv"
    assert cli.main(["run", str(tmp_path / "SystemStructure.ssd"), "--stop-time", "2", "--step-size", "0.2",
                     "--print-final", "--output", str(out)]) == 0
    printed = capsys.readouterr().out
    assert """  b.String_output = 'a "quoted", text'""" in printed and "  b.Enumeration_output = 2" in printed
    r = system_ssp.simulate(tmp_path / "SystemStructure.ssd", stop_time=2.0, step_size=0.2)
    np.testing.assert_array_equal(r.data["b.Float64_continuous_output"], r.data["vdp.x0"])
    np.testing.assert_array_equal(r.data["b.Int32_output"], r.data["stair.counter"])
    assert r.data["stair.counter"][-1] > r.data["stair.counter"][0]  # the Integer moves
    assert np.ptp(r.data["vdp.x0"]) > 0.1  # and the Real
    assert r.data["b.Boolean_output"].all() and set(r.data["b.Enumeration_output"]) == {2}
    assert set(r.data["b.String_output"]) == {'a "quoted", text'}
    from system_ssp.master.plotting import read_result
    columns, _ = read_result(out)  # the CSV, read back: the text with its comma and quotes
    assert set(columns["b.String_output"]) == {'a "quoted", text'}
