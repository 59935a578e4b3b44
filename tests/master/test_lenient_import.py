"""FMUs as other tools export them, flaws included (system_ssp.ssp.model_description): problems that
do not change the run are read with one warning per FMU, the rest are refused in one line naming
the option that changes it (--strict, --no-validate); FMUs that declare no output dependencies
are named, and the algebraic-loop refusal says what to type where the user is. The flawed FMUs
are the Modelica Reference Feedthrough (tests/data/reference_fmus, BSD-2) with its model
description changed the way the tools' exports have it (OMSimulator runs a Simulink FMU with the
first flaw in two of its published systems)."""
import shutil
import zipfile

import numpy as np
import pytest

from master_fixtures import helpers as h
from paths import DATA
import system_ssp
from system_ssp import SSPError, cli

FEEDTHROUGH = DATA / "reference_fmus" / "2.0" / "Feedthrough.fmu"
# Simulink's FMI Kit writes an Enumeration input without a variability (so "continuous") and its
# outputs without dependencies
SIMULINK = [('<ScalarVariable name="Enumeration_input" valueReference="33" causality="input" variability="discrete">',
             '<ScalarVariable name="Enumeration_input" valueReference="33" causality="input">')]
NO_DEPENDENCIES = [(f'<Unknown index="{i}" dependencies="{i - 1}" dependenciesKind="constant"/>',
                    f'<Unknown index="{i}"/>') for i in (5, 7, 9, 11, 13, 15)]


def flawed(dest, changes):
    """A copy of the Reference Feedthrough at `dest` with its modelDescription.xml changed."""
    dest.parent.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(FEEDTHROUGH) as zin, zipfile.ZipFile(dest, "w", zipfile.ZIP_DEFLATED) as zout:
        for item in zin.infolist():
            data = zin.read(item.filename)
            if item.filename == "modelDescription.xml":
                text = data.decode()
                for old, new in changes:
                    assert old in text, old
                    text = text.replace(old, new)
                data = text.encode()
            zout.writestr(item, data)
    return dest


def enumeration_system(tmp_path, changes=SIMULINK):
    """A Reference Feedthrough ('src', its Enumeration_input bound to 2) feeding the flawed one's
    Enumeration input ('sw'), the connectors typed as OMSimulator's embrace system types them."""
    flawed(tmp_path / "resources" / "Simulink.fmu", changes)
    shutil.copy(FEEDTHROUGH, tmp_path / "resources" / "Feedthrough.fmu")
    bind = ('<ssd:ParameterBinding><ssd:ParameterValues>'
            + h.ssv_text([("Enumeration_input", "Enumeration", "Option 2", None)]).split("?>", 1)[1]
            + "</ssd:ParameterValues></ssd:ParameterBinding>")
    enum = '<ssd:Connector name="{}" kind="{}"><ssc:Enumeration name="Option"/></ssd:Connector>'
    elements = (h.component("src", "Feedthrough.fmu", bindings=bind)
                + h.component("sw", "Simulink.fmu", enum.format("Enumeration_input", "input")
                              + enum.format("Enumeration_output", "output")))
    (tmp_path / "SystemStructure.ssd").write_text(h.ssd_text(
        elements, h.connection("src.Enumeration_output", "sw.Enumeration_input"),
        experiment='<ssd:DefaultExperiment startTime="0" stopTime="1"/>\n'))
    return tmp_path / "SystemStructure.ssd"


def test_a_simulink_style_fmu_runs_with_one_warning(tmp_path, capsys):
    ssd = enumeration_system(tmp_path)
    with system_ssp.System(ssd) as system:
        assert len(system.warnings) == 1
        warning = system.warnings[0]
        r = system.run(step_size=0.1)
    assert warning.startswith("component 'sw': ") and "Simulink.fmu: read leniently, as other tools read it " \
        "(strict=True refuses it)" in warning
    assert ('The variable "Enumeration_input" (line 87) is of type Enumeration and must have variability != '
            '"continuous" (read as discrete') in warning
    assert set(r.data["sw.Enumeration_output"]) == {2}
    # the command line: the same warning once on stderr, naming its own option, and the run
    assert cli.main(["run", str(ssd), "--step-size", "0.1", "--print-final"]) == 0
    printed = capsys.readouterr()
    assert printed.err.count("WARNING") == 1 and "(--strict refuses it)" in printed.err
    assert "  sw.Enumeration_output = 2" in printed.out


def test_strict_refuses_it_in_one_line_naming_the_option(tmp_path, capsys):
    ssd = enumeration_system(tmp_path)
    assert cli.main(["run", str(ssd), "--step-size", "0.1", "--strict"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and err.startswith("error: component 'sw': ")
    assert err.endswith('"continuous". (refused under --strict; without it, problems that do not change the run '
                        "are read with a warning)")
    with pytest.raises(SSPError, match=r"refused under strict=True"):
        system_ssp.System(ssd, strict=True)
    # the FMU alone, as `run X.fmu` runs it, is refused naming the user's file
    fmu = tmp_path / "resources" / "Simulink.fmu"
    assert cli.main(["run", str(fmu), "--stop-time", "1", "--step-size", "0.1", "--strict"]) == 2
    assert capsys.readouterr().err.startswith(f"error: {fmu}: modelDescription.xml does not conform")
    assert cli.main(["run", str(fmu), "--stop-time", "1", "--step-size", "0.1"]) == 0


def test_a_problem_that_would_make_the_run_wrong_is_refused_naming_no_validate(tmp_path, capsys):
    """A parameter declared initial="calculated" (FMI 2.0 allows only "exact"): which value does
    it start with? Refused, naming only that problem (not the Enumeration's, nor the start value a
    calculated variable may not have); --no-validate skips the checks and runs it."""
    calculated = [('name="Float64_fixed_parameter" valueReference="5" causality="parameter" variability="fixed"',
                   'name="Float64_fixed_parameter" valueReference="5" causality="parameter" variability="fixed" '
                   'initial="calculated"')]
    ssd = enumeration_system(tmp_path, SIMULINK + calculated)
    assert cli.main(["run", str(ssd), "--step-size", "0.1"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.endswith('conform to the FMI standard: The combination causality="parameter" and variability="fixed" '
                        'in variable "Float64_fixed_parameter" (line 51) is not allowed. (this would make the run '
                        'wrong; --no-validate reads it without the checks)')
    assert cli.main(["run", str(ssd), "--step-size", "0.1", "--no-validate"]) == 0


def test_two_variables_of_one_name_are_refused_whatever_the_options(tmp_path, capsys):
    twice = [('name="Float64_discrete_input"', 'name="Float64_continuous_input"')]
    ssd = enumeration_system(tmp_path, twice)
    for options in ([], ["--no-validate"]):
        assert cli.main(["run", str(ssd), "--step-size", "0.1", *options]) == 2
        err = capsys.readouterr().err.strip()
        assert "Float64_continuous_input" in err and "could not say which" in err and "--no-validate" not in err


def test_a_model_description_against_the_schema_is_refused_naming_no_validate(tmp_path, capsys):
    ssd = enumeration_system(tmp_path, [('name="Boolean_input" valueReference="27" causality="input"',
                                         'name="Boolean_input" valueReference="27" colour="red" causality="input"')])
    assert cli.main(["run", str(ssd), "--step-size", "0.1"]) == 2
    err = capsys.readouterr().err.strip()
    assert "modelDescription.xml does not follow the FMI schema: ERROR (line" in err and "colour" in err
    assert err.endswith("(--no-validate reads it without the checks)")


def loop_of_two(tmp_path):
    """a's discrete output feeds b's continuous input, b's continuous output a's continuous input.
    With the dependencies the Feedthroughs declare (each output on its own input) there is no
    algebraic loop; without them every output depends on every input, and the two form one."""
    flawed(tmp_path / "resources" / "NoDeps.fmu", NO_DEPENDENCIES)
    shutil.copy(FEEDTHROUGH, tmp_path / "resources" / "Feedthrough.fmu")
    bind = ('<ssd:ParameterBinding><ssd:ParameterValues>'
            + h.ssv_text([("Float64_discrete_input", "Real", "3", None)]).split("?>", 1)[1]
            + "</ssd:ParameterValues></ssd:ParameterBinding>")
    systems = {}
    for name, fmu in (("declared", "Feedthrough.fmu"), ("silent", "NoDeps.fmu")):
        text = h.ssd_text(h.component("a", fmu, bindings=bind) + h.component("b", fmu),
                          h.connection("a.Float64_discrete_output", "b.Float64_continuous_input")
                          + h.connection("b.Float64_continuous_output", "a.Float64_continuous_input"),
                          experiment='<ssd:DefaultExperiment startTime="0" stopTime="1"/>\n')
        systems[name] = tmp_path / f"{name}.ssd"
        systems[name].write_text(text)
    return systems


def test_fmus_without_output_dependencies_are_named_and_the_loop_advice_is_what_to_type(tmp_path, capsys):
    systems = loop_of_two(tmp_path)
    with system_ssp.System(systems["declared"]) as system:
        assert system.warnings == []
        declared = system.run(step_size=0.1)
    with system_ssp.System(systems["silent"]) as system:
        assert len(system.warnings) == 2
        assert system.warnings[0].startswith("component 'a': ")
        assert ("NoDeps.fmu: declares no output dependencies (ModelStructure/Outputs) for 6 of its outputs "
                "(Float64_continuous_output, Float64_discrete_output, Int32_output, Boolean_output and 2 more): each "
                "is taken to depend directly on every input") in system.warnings[0]
        with pytest.raises(SSPError) as refused:
            system.run(step_size=0.1)
        jacobi = system.run(step_size=0.1, algorithm="jacobi")
    assert str(refused.value) == (
        "algebraic loop (direct feedthrough cycle) between components: a -> b -> a (a, b declare no output "
        "dependencies, so each output is taken to depend on every input); Gauss-Seidel needs an acyclic order: break "
        "the loop or use algorithm='jacobi'")
    assert cli.main(["run", str(systems["silent"]), "--step-size", "0.1"]) == 2
    err = capsys.readouterr().err
    assert err.count("WARNING") == 2 and err.strip().splitlines()[-1].endswith(
        "Gauss-Seidel needs an acyclic order: break the loop or use --algorithm jacobi")
    assert cli.main(["run", str(systems["silent"]), "--step-size", "0.1", "--order", "b,a"]) == 2
    assert "(use --algorithm jacobi, or break the loop)" in capsys.readouterr().err
    assert set(declared.data["b.Float64_continuous_output"][1:]) == {3.0}
    np.testing.assert_array_equal(jacobi.data["a.Float64_continuous_input"][2:], 3.0)
