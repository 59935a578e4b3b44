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


@pytest.mark.parametrize("version, kind", [("1.0", "co-simulation"), ("3.0", "co-simulation")])
def test_fmus_of_other_fmi_versions_are_refused_naming_the_version(version, kind, tmp_path, capsys):
    """FMI 1.0 is refused, not imported (components.unsupported_fmu says why); FMI 3.0 waits for its
    importer. One line naming the user's file (not a temporary copy) and the version, exit 2."""
    path = DATA / "reference_fmus" / version / "Dahlquist.fmu"
    assert cli.main(["run", str(path), "--step-size", "0.1"]) == 2
    err = capsys.readouterr().err.strip()
    assert err == (f"error: {path} is an FMI {version} {kind} FMU; this master runs FMI 2.0 co-simulation FMUs"
                   + (" and does not import FMI 1.0 (superseded in 2014): export it as FMI 2.0" if version == "1.0"
                      else " (export it as FMI 2.0)"))
    ssd = single_fmu_system(path, tmp_path)  # as a component of a system
    with pytest.raises(system_ssp.SSPError, match=rf"component 'Dahlquist': .*Dahlquist.fmu is an FMI {version} "):
        system_ssp.System(ssd)
