"""Where a run's communication step comes from, first found of: the caller (--step-size), our
annotation (nc:Master stepSize), OSP's annotation (libcosim's osp:FixedStepAlgorithm
baseStepSize, which also asks for libcosim's Jacobi-type algorithm), the FMUs' DefaultExperiment
stepSize (the smallest); the run and `info` say which. Systems of Modelica Reference FMUs
(tests/data/reference_fmus) written here in each shape."""
import shutil

import pytest

from master_fixtures import helpers as h
from paths import DATA
import system_ssp
from system_ssp import cli
from system_ssp.errors import SSPError

FMUS = DATA / "reference_fmus" / "2.0"
NC = '<ssd:Annotations><ssc:Annotation type="org.neighbor-cosim.master">' \
     '<nc:Master xmlns:nc="https://neighbor-cosim.org/ssp/master" {}/></ssc:Annotation></ssd:Annotations>'


def osp(step):
    return ('<ssd:Annotations><ssc:Annotation type="com.opensimulationplatform"><osp:Algorithm '
            'xmlns:osp="http://opensimulationplatform.com/SSP/OSPAnnotations">'
            f'<osp:FixedStepAlgorithm baseStepSize="{step}"/></osp:Algorithm></ssc:Annotation></ssd:Annotations>')


def system(tmp_path, models, experiment_annotations="", system_annotations=""):
    """Reference FMUs side by side (no connections), each under its own name."""
    (tmp_path / "resources").mkdir()
    for m in models:
        shutil.copy(FMUS / f"{m}.fmu", tmp_path / "resources" / f"{m}.fmu")
    text = h.ssd_text("".join(h.component(m, f"{m}.fmu") for m in models), system_extra=system_annotations,
                      experiment=f'<ssd:DefaultExperiment startTime="0" stopTime="1">{experiment_annotations}'
                                 "</ssd:DefaultExperiment>\n")
    (tmp_path / "SystemStructure.ssd").write_text(text)
    return tmp_path / "SystemStructure.ssd"


def line_of(path, text):
    return next(i for i, line in enumerate(path.read_text().splitlines(), 1) if text in line)


def test_the_smallest_fmu_default_experiment_step(tmp_path):
    ssd = system(tmp_path, ["Dahlquist", "VanDerPol"])  # 0.1 s and 0.01 s
    r = system_ssp.simulate(ssd)
    assert (r.step_size, r.steps, r.algorithm) == (0.01, 100, "gauss-seidel")
    assert r.step_size_source == "the smallest DefaultExperiment stepSize of the FMUs (VanDerPol)"


def test_osp_base_step_over_the_fmus_and_its_algorithm(tmp_path, capsys):
    ssd = system(tmp_path, ["Dahlquist", "VanDerPol"], experiment_annotations=osp("0.05"))
    at = f"{ssd}:{line_of(ssd, 'osp:FixedStepAlgorithm')}"
    r = system_ssp.simulate(ssd)
    assert (r.step_size, r.steps, r.algorithm) == (0.05, 20, "jacobi")
    assert r.step_size_source == f"osp:FixedStepAlgorithm baseStepSize at {at}"
    assert system_ssp.simulate(ssd, algorithm="gauss-seidel").algorithm == "gauss-seidel"
    assert cli.main(["run", str(ssd.parent)]) == 0  # the system's folder
    assert f"step size:   0.05 s from osp:FixedStepAlgorithm baseStepSize at {at}" in capsys.readouterr().out
    assert cli.main(["info", str(ssd)]) == 0
    assert f"step size: 0.05 s from osp:FixedStepAlgorithm baseStepSize at {at}" in capsys.readouterr().out


def test_our_annotation_over_osp_and_the_caller_over_both(tmp_path, capsys):
    ssd = system(tmp_path, ["Dahlquist"], experiment_annotations=osp("0.05"),
                 system_annotations=NC.format('stepSize="0.25" algorithm="gauss-seidel"'))
    r = system_ssp.simulate(ssd)
    assert (r.step_size, r.steps, r.algorithm) == (0.25, 4, "gauss-seidel")
    assert r.step_size_source.startswith("nc:Master stepSize at ")
    r = system_ssp.simulate(ssd, step_size=0.5)
    assert (r.step_size, r.step_size_source) == (0.5, "as requested")
    assert cli.main(["run", str(ssd), "--step-size", "0.5"]) == 0
    assert "step size:" not in capsys.readouterr().out  # the caller knows where theirs came from


def test_no_step_anywhere_names_every_place_one_may_be(tmp_path):
    ssd = system(tmp_path, ["Resource"])  # Resource's DefaultExperiment has no stepSize
    with pytest.raises(SSPError, match=r"no step size: pass step_size \(CLI --step-size\), give one in the "
                                       r"org.neighbor-cosim.master annotation \(nc:Master stepSize\), OSP's "
                                       r"\(osp:FixedStepAlgorithm baseStepSize\) or OMSimulator's "
                                       r"\(oms:FixedStepMaster stepSize\), or use FMUs whose DefaultExperiment has "
                                       r"a stepSize"):
        system_ssp.simulate(ssd)


@pytest.mark.parametrize("value", ["0", "-1e-3", "fast", "inf"])
def test_a_bad_osp_base_step_names_its_line(tmp_path, value):
    ssd = system(tmp_path, ["Dahlquist"], experiment_annotations=osp(value))
    with pytest.raises(SSPError, match=rf"^{ssd}:{line_of(ssd, 'osp:FixedStepAlgorithm')}: .*baseStepSize"):
        system_ssp.System(ssd)


def test_omsimulator_fixed_step_master_after_osp(tmp_path, capsys):
    """OMSimulator writes its master's step in its own annotation of the root system
    (org.openmodelica: oms:SimulationInformation/oms:FixedStepMaster stepSize)."""
    oms = ('<ssd:Annotations><ssc:Annotation type="org.openmodelica"><oms:Annotations xmlns:oms="https://raw.'
           'githubusercontent.com/OpenModelica/OMSimulator/master/schema/oms.xsd"><oms:SimulationInformation>'
           '<oms:FixedStepMaster description="oms-ma" stepSize="0.125000" relativeTolerance="0.000100"/>'
           '</oms:SimulationInformation></oms:Annotations></ssc:Annotation></ssd:Annotations>')
    ssd = system(tmp_path, ["Dahlquist"], system_annotations=oms)
    r = system_ssp.simulate(ssd)
    assert (r.step_size, r.steps, r.algorithm) == (0.125, 8, "gauss-seidel")
    assert r.step_size_source == f"oms:FixedStepMaster stepSize at {ssd}:{line_of(ssd, 'oms:FixedStepMaster')}"
    ssd.write_text(ssd.read_text().replace("<ssd:DefaultExperiment startTime=\"0\" stopTime=\"1\">",
                                           "<ssd:DefaultExperiment startTime=\"0\" stopTime=\"1\">" + osp("0.25")))
    assert system_ssp.simulate(ssd).step_size == 0.25  # a file written for both tools: OSP's, as documented
