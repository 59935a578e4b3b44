"""Systems in the shapes other tools write them, with Modelica Reference FMUs
(tests/data/reference_fmus) as components; each checked against values derived by hand and
against FMPy running the same FMU with the same start values."""
import shutil

import fmpy
import numpy as np
import pytest

from master_fixtures import helpers as h
from paths import DATA
import system_ssp
from system_ssp.errors import SSPError
from system_ssp.master.planning import make_plan

FMUS = DATA / "reference_fmus" / "2.0"
SSM_HEAD = ('<?xml version="1.0" encoding="UTF-8"?>\n<ssm:ParameterMapping version="1.0" '
            'xmlns:ssm="http://ssp-standard.org/SSP1/SystemStructureParameterMapping" '
            'xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon">\n')


def balls(tmp_path, system_head="", files=None):
    """Two Reference BouncingBalls, bb1 and bb2, unconnected."""
    (tmp_path / "resources").mkdir()
    shutil.copy(FMUS / "BouncingBall.fmu", tmp_path / "resources" / "BouncingBall.fmu")
    for rel, text in (files or {}).items():
        (tmp_path / rel).write_text(text)
    text = h.ssd_text(h.component("bb1", "BouncingBall.fmu") + h.component("bb2", "BouncingBall.fmu"),
                      system_head=system_head,
                      experiment='<ssd:DefaultExperiment startTime="0" stopTime="1"/>\n')
    (tmp_path / "SystemStructure.ssd").write_text(text)
    return tmp_path / "SystemStructure.ssd"


def fmpy_ball(stop, step, **start):
    return fmpy.simulate_fmu(str(FMUS / "BouncingBall.fmu"), stop_time=stop, output_interval=step,
                             start_values=start, fmi_type="CoSimulation")


def test_an_ssm_as_omsimulator_writes_it(tmp_path):
    """OMSimulator exports an SSM template with an entry per parameter whose source is empty, to be
    filled in by the user (its test suite's ECS_HW.ssm); one source may feed several targets. The
    template entries map nothing; 'gravity' reaches both balls, halved for bb2."""
    ssm = (SSM_HEAD
           + '<ssm:MappingEntry source="" target="bb1.e"/>\n<ssm:MappingEntry source="" target="bb2.g"/>\n'
           + '<ssm:MappingEntry source="gravity" target="bb1.g"/>\n'
           + '<ssm:MappingEntry source="gravity" target="bb2.g"><ssc:LinearTransformation factor="0.5"/>'
           + "</ssm:MappingEntry>\n</ssm:ParameterMapping>\n")
    ssv = h.ssv_text([("gravity", "Real", "-3.0", None), ("bb2.e", "Real", "0.5", None)])
    bind = ('<ssd:ParameterBindings><ssd:ParameterBinding source="values.ssv">'
            '<ssd:ParameterMapping source="mapping.ssm"/></ssd:ParameterBinding></ssd:ParameterBindings>')
    ssd = balls(tmp_path, bind, {"values.ssv": ssv, "mapping.ssm": ssm})
    with system_ssp.System(ssd) as system:
        params = {f"{system.comps[ci].name}.{var}": value for (ci, var), value in make_plan(system).params.items()}
    assert params == {"bb1.g": -3.0, "bb2.g": -1.5, "bb2.e": 0.5}  # bb1.e keeps its start value 0.7
    r = system_ssp.simulate(ssd, step_size=0.01, stop_time=1.0)
    for name, start in (("bb1", {"g": -3.0}), ("bb2", {"g": -1.5, "e": 0.5})):
        expected = fmpy_ball(1.0, 0.01, **start)
        np.testing.assert_array_equal(r.data[f"{name}.h"], expected["h"])
    # by hand: free fall from 1 m under g until the first bounce at sqrt(2 / |g|) s
    assert r.data["bb1.h"][50] == pytest.approx(1 - 3.0 * 0.5 ** 2 / 2, abs=2e-3)
    assert r.data["bb2.h"][50] == pytest.approx(1 - 1.5 * 0.5 ** 2 / 2, abs=2e-3)


def test_an_ssm_entry_without_a_source_attribute_is_refused_by_line(tmp_path):
    ssm = SSM_HEAD + '<ssm:MappingEntry target="bb1.g"/>\n</ssm:ParameterMapping>\n'
    bind = ('<ssd:ParameterBindings><ssd:ParameterBinding source="values.ssv">'
            '<ssd:ParameterMapping source="mapping.ssm"/></ssd:ParameterBinding></ssd:ParameterBindings>')
    ssd = balls(tmp_path, bind, {"values.ssv": h.ssv_text([("g", "Real", "-3", None)]), "mapping.ssm": ssm})
    with pytest.raises(SSPError, match=r"mapping.ssm:3: schema violation: .*'source' is required"):
        system_ssp.System(ssd)
    with pytest.raises(SSPError, match=r"mapping.ssm:3: <MappingEntry> needs a source attribute"):
        system_ssp.System(ssd, validate=False)
