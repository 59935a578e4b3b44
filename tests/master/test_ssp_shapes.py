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
from system_ssp import cli
from system_ssp.errors import SSPError
from system_ssp.master.planning import make_plan

FMUS = DATA / "reference_fmus" / "2.0"
SSM_HEAD = ('<?xml version="1.0" encoding="UTF-8"?>\n<ssm:ParameterMapping version="1.0" '
            'xmlns:ssm="http://ssp-standard.org/SSP1/SystemStructureParameterMapping" '
            'xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon">\n')


def balls(tmp_path, system_head="", files=None):
    """Two Reference BouncingBalls, bb1 and bb2, unconnected."""
    (tmp_path / "resources").mkdir(parents=True)
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
    template entries map nothing; 'gravity' reaches both balls, halved for bb2. 'bb2.e', which the
    mapping leaves out, is not applied (SSP 1.0 section 7), with a warning saying that
    OMSimulator would apply it by its name."""
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
        assert len(system.warnings) == 1
        assert f"{ssd}:" in system.warnings[0]  # the binding's file and line
        assert ("the parameter mapping of this binding leaves out 1 parameter of its set that names a variable "
                "(bb2.e): not applied, as SSP 1.0 section 7 says (OMSimulator applies them by their names") \
            in system.warnings[0]
    assert params == {"bb1.g": -3.0, "bb2.g": -1.5}  # bb1.e and bb2.e keep their start value 0.7
    r = system_ssp.simulate(ssd, step_size=0.01, stop_time=1.0)
    for name, start in (("bb1", {"g": -3.0}), ("bb2", {"g": -1.5})):
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


def test_a_cad_tools_parameter_set_of_which_the_mapping_takes_one(tmp_path, caplog):
    """The shape of OMSimulator's embrace system (its test suite's ECS_HW.ssm and RAPID_Systems
    .ssv): a CAD tool's parameter set (SSV version 2.0 in an SSP 1.0 system, hierarchical part
    names, units written "[m]" beside an ssc:Unit "m") bound to the root system with an SSM that
    maps one of its parameters to two components and leaves template entries (source "") for the
    rest. The mapped value reaches both balls' heights (as OMSimulator prints pipeB.L and pipeA.L
    equal to the part's pipe length); the CAD parameters the mapping leaves out name nothing here
    and are not applied, without a word, even one the set gives twice with two values (its
    embrace_TwoConf's set does); "[m]" is read as "m" with one warning. Before: "unknown component
    'product_subAssembly1'". A parameter given twice that the mapping applies is refused."""
    cad = "product_subAssembly1.part_testPipe1"
    ssv = ('<?xml version="1.0" encoding="UTF-8"?>\n<ssv:ParameterSet '
           'xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues" '
           'xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon" version="2.0" name="product_mainAssembly">'
           '<ssv:Parameters>'
           f'<ssv:Parameter name="{cad}.parameterSet_inputParameters.parameter_pipeRadius">'
           '<ssv:Real unit="[m]" value="0.005"/></ssv:Parameter>'
           f'<ssv:Parameter name="{cad}.parameterSet_outputParameters.parameter_pipeLength">'
           '<ssv:Real unit="[m]" value="0.976535328081166"/></ssv:Parameter>'
           f'<ssv:Parameter name="{cad}.parameterSet_inputParameters.parameter_testInteger">'
           '<ssv:Integer value="7"/></ssv:Parameter>'
           f'<ssv:Parameter name="{cad}.geometricalSet_constructionGeometry.parameter_X">'
           '<ssv:Real unit="[m]" value="0.05"/></ssv:Parameter>'
           f'<ssv:Parameter name="{cad}.geometricalSet_constructionGeometry.parameter_X">'
           '<ssv:Real unit="[m]" value="-0.0025"/></ssv:Parameter>'
           '</ssv:Parameters><ssv:Units><ssc:Unit name="m"><ssc:BaseUnit m="1"/></ssc:Unit></ssv:Units>'
           '</ssv:ParameterSet>\n')
    ssm = (SSM_HEAD + '<ssm:MappingEntry source="" target="bb1.e"/>\n<ssm:MappingEntry source="" target="bb2.e"/>\n'
           f'<ssm:MappingEntry source="{cad}.parameterSet_outputParameters.parameter_pipeLength" target="bb1.h"/>\n'
           f'<ssm:MappingEntry source="{cad}.parameterSet_outputParameters.parameter_pipeLength" target="bb2.h"/>\n'
           "</ssm:ParameterMapping>\n")
    bind = ('<ssd:ParameterBindings><ssd:ParameterBinding source="resources/cad.ssv">'
            '<ssd:ParameterMapping source="resources/ECS.ssm"/></ssd:ParameterBinding></ssd:ParameterBindings>')
    ssd = balls(tmp_path, bind, {"resources/cad.ssv": ssv, "resources/ECS.ssm": ssm})
    with system_ssp.System(ssd) as system:
        assert system.warnings == []
        r = system.run(step_size=0.01, stop_time=0.5)
    assert r.data["bb1.h"][0] == r.data["bb2.h"][0] == 0.976535328081166
    np.testing.assert_array_equal(r.data["bb1.h"], fmpy_ball(0.5, 0.01, h=0.976535328081166)["h"])
    bracketed = [rec.getMessage() for rec in caplog.records if "'[m]'" in rec.getMessage()]
    assert len(bracketed) == 1 and "cad.ssv:2 (mapped by " in bracketed[0] and "ECS.ssm:5)" in bracketed[0]
    assert "unit '[m]' has no definition; read as 'm'" in bracketed[0]
    twice = ssm.replace("parameterSet_outputParameters.parameter_pipeLength\" target=\"bb2.h",
                        "geometricalSet_constructionGeometry.parameter_X\" target=\"bb2.h")
    assert twice != ssm
    (tmp_path / "resources" / "ECS.ssm").write_text(twice)
    with pytest.raises(SSPError, match=r"cad.ssv:2: parameter 'product_subAssembly1.part_testPipe1."
                                       r"geometricalSet_constructionGeometry.parameter_X' is already set on line 2"):
        system_ssp.System(ssd)


def test_an_ssm_entry_that_maps_nothing_is_refused_by_its_line(tmp_path):
    """An entry whose source the parameter set does not have, and one whose target names no
    variable: one line each, naming the .ssm file and the entry's line."""
    bind = ('<ssd:ParameterBindings><ssd:ParameterBinding source="values.ssv">'
            '<ssd:ParameterMapping source="mapping.ssm"/></ssd:ParameterBinding></ssd:ParameterBindings>')
    ssv = h.ssv_text([("gravity", "Real", "-3", None)])
    ssm = SSM_HEAD + '<ssm:MappingEntry source="gravty" target="bb1.g"/>\n</ssm:ParameterMapping>\n'
    ssd = balls(tmp_path / "a", bind, {"values.ssv": ssv, "mapping.ssm": ssm})
    with pytest.raises(SSPError, match=r"mapping.ssm:3: mapping entry 'gravty' -> 'bb1.g' maps nothing: the "
                                       r"parameter set bound at .*SystemStructure.ssd:\d+ has no parameter 'gravty' "
                                       r"\(did you mean 'gravity'\?\)"):
        system_ssp.System(ssd)
    ssm = SSM_HEAD + '<ssm:MappingEntry source="gravity" target="bb1.gg"/>\n</ssm:ParameterMapping>\n'
    ssd = balls(tmp_path / "b", bind, {"values.ssv": ssv, "mapping.ssm": ssm})
    with system_ssp.System(ssd) as system, pytest.raises(
            SSPError, match=r"values.ssv:\d+ \(mapped by .*mapping.ssm:3\): .*component 'bb1' has no variable 'gg'"):
        make_plan(system)


def gain_alone(tmp_path, fmus, bind, files, ssp2=False):
    """One fixture gain (y = k u + b, u and b in m), its inputs unconnected, bound by `bind`."""
    text = h.ssd_text(h.component("gain", "gain.fmu", bindings=bind),
                      experiment='<ssd:DefaultExperiment startTime="0" stopTime="1"/>\n')
    if ssp2:
        text = as_ssp2(text)
        files = {name: as_ssp2(content) for name, content in files.items()}
    return h.write_system(tmp_path, fmus, {"gain.fmu": "gain"}, text, extra_files=files)


def test_mapping_entries_with_transformations_as_omsimulator_writes_them_in_ssp2(fixture_fmus, tmp_path):
    """The shape of OMSimulator's LinearTransformation3 (SSP 2.0 system, parameter set and
    mapping): two parameters mapped with a LinearTransformation each, to a gain's k and its
    unconnected input u. OMSimulator prints k = 4 * 2 + 5 = 13, u = 2 * 2 + 10 = 14, y = 182."""
    ssv = h.ssv_text([("mapped_Gain_u", "Real", "2.0", None), ("mapped_Gain_k", "Real", "2.0", None)])
    ssm = (SSM_HEAD + '<ssm:MappingEntry source="mapped_Gain_u" target="u"><ssc:LinearTransformation factor="2" '
           'offset="10"/></ssm:MappingEntry>\n<ssm:MappingEntry source="mapped_Gain_k" target="k">'
           '<ssc:LinearTransformation factor="4" offset="5"/></ssm:MappingEntry>\n</ssm:ParameterMapping>\n')
    bind = '<ssd:ParameterBinding source="m.ssv"><ssd:ParameterMapping source="m.ssm"/></ssd:ParameterBinding>'
    ssd = gain_alone(tmp_path, fixture_fmus, bind, {"m.ssv": ssv, "m.ssm": ssm}, ssp2=True)
    assert 'version="2.0"' in (tmp_path / "m.ssm").read_text()
    r = system_ssp.simulate(ssd, step_size=0.5)
    assert (r.data["gain.u"][0], r.data["gain.y"][0], r.final["gain.y"]) == (14.0, 182.0, 182.0)


@pytest.mark.parametrize("suppress, b", [("", 2 * 2.0 + 1), (' suppressUnitConversion="true"', 2 * 0.002 + 1)])
def test_a_mapped_value_is_transformed_after_its_unit_conversion(fixture_fmus, tmp_path, suppress, b):
    """SSP 1.0 section 7: the transformation acts on the value converted to the target's unit
    (0.002 km -> 2 m, then 2 x + 1 = 5 m), or instead of the conversion when the entry suppresses
    it (2 * 0.002 + 1 = 1.004 m). The mapping is inline, on the component's binding."""
    ssv = h.ssv_text([("bias", "Real", "0.002", "km")], units='<ssc:Unit name="km"><ssc:BaseUnit m="1" '
                     'factor="1000"/></ssc:Unit>')
    bind = ('<ssd:ParameterBinding source="b.ssv"><ssd:ParameterMapping><ssm:ParameterMapping version="1.0">'
            f'<ssm:MappingEntry source="bias" target="b"{suppress}><ssc:LinearTransformation factor="2" offset="1"/>'
            '</ssm:MappingEntry></ssm:ParameterMapping></ssd:ParameterMapping></ssd:ParameterBinding>')
    ssd = gain_alone(tmp_path, fixture_fmus, bind, {"b.ssv": ssv})
    r = system_ssp.simulate(ssd, step_size=0.5)
    assert r.data["gain.y"][0] == pytest.approx(b, rel=1e-15)  # u = 0: y = b


def test_a_mapping_on_a_nested_systems_binding(fixture_fmus, tmp_path):
    """A nested system's binding with a mapping: its targets are named inside that system (its
    component deeper.g2's k, its own parameter connector x0p); the run equals the nested system
    bound without a mapping."""
    plain = nested_system(tmp_path / "plain", fixture_fmus)
    mapped = nested_system(tmp_path / "mapped", fixture_fmus)
    text = mapped.read_text()
    inline_ssm = ('<ssd:ParameterMapping><ssm:ParameterMapping version="1.0">'
                  '<ssm:MappingEntry source="gain_of_g2" target="deeper.g2.k"/>'
                  '<ssm:MappingEntry source="start" target="x0p"/></ssm:ParameterMapping></ssd:ParameterMapping>')
    text = text.replace('name="deeper.g2.k"', 'name="gain_of_g2"').replace('name="x0p"><ssv:', 'name="start"><ssv:')
    text = text.replace("</ssd:ParameterValues></ssd:ParameterBinding>",
                        "</ssd:ParameterValues>" + inline_ssm + "</ssd:ParameterBinding>", 1)
    assert text.count("gain_of_g2") == 2 and text.count('"start"') == 2
    mapped.write_text(text)
    a = system_ssp.simulate(plain, step_size=0.1, stop_time=0.3)
    b = system_ssp.simulate(mapped, step_size=0.1, stop_time=0.3)
    for name in a.names:
        np.testing.assert_array_equal(a.data[name], b.data[name], err_msg=name)
    assert b.data["sub.integ.x"][0] == 0.5


@pytest.fixture(scope="module")
def fixture_fmus(tmp_path_factory):
    return h.build_fixture_fmus(tmp_path_factory.mktemp("shapes_fmus"))


def top_level_connectors_system(tmp_path, fmus, extra_connection=""):
    """As OMSimulator builds one (its import_export_parameters test): the root system has an input
    connector and a parameter connector, both given values by a parameter set bound to the system;
    the input feeds a gain's input, the parameter its gain. y = k u + b with b = 1 m."""
    conns = ('<ssd:Connectors><ssd:Connector name="Input_cref" kind="input"><ssc:Real unit="m"/></ssd:Connector>'
             '<ssd:Connector name="k_cref" kind="parameter"><ssc:Real/></ssd:Connector></ssd:Connectors>')
    ssv = h.ssv_text([("Input_cref", "Real", "-20", None), ("k_cref", "Real", "3", None),
                      ("gain.b", "Real", "1", None)])
    bind = '<ssd:ParameterBindings><ssd:ParameterBinding source="root.ssv"/></ssd:ParameterBindings>'
    el = (h.component("gain", "gain.fmu", '<ssd:Connector name="u" kind="input"><ssc:Real/></ssd:Connector>'
                      '<ssd:Connector name="k" kind="parameter"><ssc:Real/></ssd:Connector>'
                      '<ssd:Connector name="y" kind="output"><ssc:Real/></ssd:Connector>')
          + h.component("integ", "integ.fmu", '<ssd:Connector name="u" kind="input"><ssc:Real/></ssd:Connector>'
                        '<ssd:Connector name="x" kind="output"><ssc:Real/></ssd:Connector>'))
    co = ('<ssd:Connection startConnector="Input_cref" endElement="gain" endConnector="u"/>\n'
          '<ssd:Connection startConnector="k_cref" endElement="gain" endConnector="k"/>\n'
          + h.connection("gain.y", "integ.u") + extra_connection)
    return h.write_system(tmp_path, fmus, {"gain.fmu": "gain", "integ.fmu": "integrator"},
                          h.ssd_text(el, co, system_head=conns + bind), extra_files={"root.ssv": ssv})


def test_top_level_input_and_parameter_connectors_bound_by_a_parameter_set(fixture_fmus, tmp_path):
    ssd = top_level_connectors_system(tmp_path, fixture_fmus)
    r = system_ssp.simulate(ssd, step_size=0.5, stop_time=2.0)
    # by hand: u = -20 m held, k = 3, b = 1 m: y = -59 m; the integrator: x(2 s) = -59 * 2 = -118
    assert set(r.data["gain.u"]) == {-20.0} and set(r.data["gain.y"]) == {-59.0}
    assert r.final["integ.x"] == pytest.approx(-118.0)
    r = system_ssp.simulate(ssd, step_size=0.5, stop_time=2.0, parameters={"Input_cref": 4.0})  # as --set does
    assert r.final["gain.y"] == 13.0


@pytest.mark.parametrize("values", [
    [("k_cref", "Real", "3", None), ("gain.k", "Real", "10", None)],  # OMSimulator's import_export_parameters1
    [("gain.k", "Real", "10", None), ("k_cref", "Real", "3", None)],
])
def test_a_connected_system_parameter_wins_over_the_components_own_binding(fixture_fmus, tmp_path, values):
    """As OMSimulator has it (its import_export_parameters1 binds k_cref = 30, connected to
    addP.k1, then addP.k1 = 10 in the same set, and gets 30): the connected system parameter gives
    gain.k its value whichever comes first in the set. The caller's values still come last and
    win (--set gain.k=5)."""
    ssd = top_level_connectors_system(tmp_path, fixture_fmus)
    (tmp_path / "root.ssv").write_text(h.ssv_text([("Input_cref", "Real", "-20", None), ("gain.b", "Real", "1", None)]
                                                  + values))
    r = system_ssp.simulate(ssd, step_size=0.5, stop_time=2.0)
    assert set(r.data["gain.y"]) == {3 * -20.0 + 1}
    r = system_ssp.simulate(ssd, step_size=0.5, stop_time=2.0, parameters={"gain.k": 5.0})
    assert set(r.data["gain.y"]) == {5 * -20.0 + 1}


def test_a_top_level_input_also_fed_by_an_output_is_refused(fixture_fmus, tmp_path):
    ssd = top_level_connectors_system(tmp_path, fixture_fmus, h.connection("integ.x", "gain.u"))
    with pytest.raises(SSPError, match=r"SystemStructure.ssd:\d+: gain.u gets the value of system input "
                                       r"'Input_cref' and is also connected to an output"):
        system_ssp.System(ssd)


def as_ssp2(text):
    """An SSP 1.0 file's text as SSP 2.0 writes it: version 2.0, scalars in the sized types."""
    return (text.replace('version="1.0"', 'version="2.0"').replace('<?xml version="2.0"', '<?xml version="1.0"')
            .replace("<ssc:Real", "<ssc:Float64")
            .replace("<ssv:Real ", "<ssv:Float64 ").replace("<ssv:Integer ", "<ssv:Int32 "))


def test_an_ssp2_system_runs_as_its_ssp1_twin(fixture_fmus, tmp_path):
    """SSP 2.0 files (checked against SSP 2.0's schemas, vendored in system_ssp/ssp/schema_ssp2)
    with Float64 connectors and Float64/Int32 values run as the same system in SSP 1.0 does."""
    one = top_level_connectors_system(tmp_path / "one", fixture_fmus)
    two_dir = tmp_path / "two"
    shutil.copytree(one.parent, two_dir)
    for name in ("SystemStructure.ssd", "root.ssv"):
        path = two_dir / name
        path.write_text(as_ssp2(path.read_text()))
    assert 'version="2.0"' in (two_dir / "root.ssv").read_text() and "<ssc:Float64" in (two_dir / one.name).read_text()
    a = system_ssp.simulate(one, step_size=0.5, stop_time=2.0)
    b = system_ssp.simulate(two_dir / one.name, step_size=0.5, stop_time=2.0)
    assert a.names == b.names and b.final["integ.x"] == pytest.approx(-118.0)
    for name in a.names:
        np.testing.assert_array_equal(a.data[name], b.data[name])


@pytest.mark.parametrize("change, message", [
    (('<ssc:Float64 unit="m"/>', '<ssc:Clock/>'), r"connector 'Input_cref' is a clock connector \(ssc:Clock\) of "
                                                 r"SSP 2.0: it needs FMI 3.0 components"),
    (('<ssc:Float64 unit="m"/>', '<ssc:Float64 unit="m"/><ssc:Dimension size="3"/>'),
     r"connector 'Input_cref' is an array connector \(ssc:Dimension\) of SSP 2.0"),
    (('version="2.0"', 'version="3.0"'), r"ssd:\d+: SSP version '3.0': this reader knows SSP 1.x and 2.0"),
    (("<ssd:Connectors>", "<ssd:Connectors><ssd:Unknown/>"), r":\d+: schema violation: .*Unknown"),
])
def test_what_ssp2_adds_for_fmi3_is_refused_by_name(fixture_fmus, tmp_path, change, message):
    ssd = top_level_connectors_system(tmp_path, fixture_fmus)
    ssd.write_text(as_ssp2(ssd.read_text()).replace(*change, 1))
    with pytest.raises(SSPError, match=message):
        system_ssp.System(ssd)


def test_an_ssp2_array_value_is_refused_by_name(fixture_fmus, tmp_path):
    ssd = top_level_connectors_system(tmp_path, fixture_fmus)
    ssd.write_text(as_ssp2(ssd.read_text()))
    ssv = tmp_path / "root.ssv"
    ssv.write_text(as_ssp2(ssv.read_text()).replace('value="-20"', 'value="-20 -21 -22"'))
    with pytest.raises(SSPError, match=r"root.ssv:\d+: parameter 'Input_cref': '-20 -21 -22' is an array value "
                                       r"\(SSP 2.0\): it needs FMI 3.0 components"):
        system_ssp.System(ssd)


def _real(name, kind, unit=None):
    u = f' unit="{unit}"' if unit else ""
    return f'<ssd:Connector name="{name}" kind="{kind}"><ssc:Real{u}/></ssd:Connector>'


def _sys_connection(start, end):
    """A connection whose ends are 'element.connector' or a bare system connector name."""
    def attrs(which, e):
        element, _, connector = e.rpartition(".")
        return (f'{which}Element="{element}" ' if element else "") + f'{which}Connector="{connector}"'
    return f'<ssd:Connection {attrs("start", start)} {attrs("end", end)}/>\n'


def nested_system(tmp_path, fmus, root_binding=""):
    """gain (root) -> sub.u -> sub.deeper.a -> sub.deeper.g2 -> sub.deeper.b -> sub.integ -> sub.y ->
    gain.u. The sub system binds deeper.g2.k = 2 and its parameter connector x0p = 0.5, which goes to
    integ.x0; the root binds gain.b = 1 (and, in a variant, sub.deeper.g2.k = 3: the outer wins)."""
    deeper = ('<ssd:System name="deeper"><ssd:Connectors>' + _real("a", "input") + _real("b", "output")
              + "</ssd:Connectors><ssd:Elements>" + h.component("g2", "gain.fmu") + "</ssd:Elements>"
              + "<ssd:Connections>" + _sys_connection("a", "g2.u") + _sys_connection("g2.y", "b")
              + "</ssd:Connections></ssd:System>")
    sub_bind = ('<ssd:ParameterBindings><ssd:ParameterBinding><ssd:ParameterValues>'
                + h.ssv_text([("deeper.g2.k", "Real", "2", None), ("x0p", "Real", "0.5", None)])
                .split("?>", 1)[1] + "</ssd:ParameterValues></ssd:ParameterBinding></ssd:ParameterBindings>")
    sub = ('<ssd:System name="sub"><ssd:Connectors>' + _real("u", "input", "m") + _real("y", "output")
           + _real("x0p", "parameter") + "</ssd:Connectors>" + sub_bind + "<ssd:Elements>"
           + h.component("integ", "integ.fmu") + deeper + "</ssd:Elements><ssd:Connections>"
           + _sys_connection("u", "deeper.a") + _sys_connection("deeper.b", "integ.u")
           + _sys_connection("integ.x", "y") + _sys_connection("x0p", "integ.x0")
           + "</ssd:Connections></ssd:System>")
    root_values = [("gain.b", "Real", "1", None)] + ([("sub.deeper.g2.k", "Real", root_binding, None)]
                                                      if root_binding else [])
    (tmp_path / "root.ssv").parent.mkdir(parents=True, exist_ok=True)
    bind = '<ssd:ParameterBindings><ssd:ParameterBinding source="root.ssv"/></ssd:ParameterBindings>'
    text = h.ssd_text(h.component("gain", "gain.fmu") + sub,
                      _sys_connection("gain.y", "sub.u") + _sys_connection("sub.y", "gain.u"), system_head=bind)
    return h.write_system(tmp_path, fmus, {"gain.fmu": "gain", "integ.fmu": "integrator"}, text,
                          extra_files={"root.ssv": h.ssv_text(root_values)})


def flat_twin(tmp_path, fmus, k):
    """The same components, flat, under their dotted names, with the values bound directly."""
    comps = (h.component("gain", "gain.fmu") + h.component("sub.integ", "integ.fmu")
             + h.component("sub.deeper.g2", "gain.fmu"))
    conns = (_sys_connection("gain.y", "sub.deeper.g2.u") + _sys_connection("sub.deeper.g2.y", "sub.integ.u")
             + _sys_connection("sub.integ.x", "gain.u"))
    values = [("gain.b", "Real", "1", None), ("sub.deeper.g2.k", "Real", str(k), None),
              ("sub.integ.x0", "Real", "0.5", None)]
    bind = '<ssd:ParameterBindings><ssd:ParameterBinding source="root.ssv"/></ssd:ParameterBindings>'
    return h.write_system(tmp_path, fmus, {"gain.fmu": "gain", "integ.fmu": "integrator"},
                          h.ssd_text(comps, conns, system_head=bind), extra_files={"root.ssv": h.ssv_text(values)})


@pytest.mark.parametrize("root_k, k", [("", 2.0), ("3", 3.0)])
def test_a_nested_system_runs_as_its_flat_twin(fixture_fmus, tmp_path, root_k, k):
    ssd = nested_system(tmp_path / "nested", fixture_fmus, root_k)
    r = system_ssp.simulate(ssd, step_size=0.1, stop_time=0.3)
    assert set(r.names) == {"gain.u", "gain.y", "sub.integ.u", "sub.integ.x", "sub.integ.steps", "sub.deeper.g2.u",
                            "sub.deeper.g2.y"}
    twin = system_ssp.simulate(flat_twin(tmp_path / "flat", fixture_fmus, k), step_size=0.1, stop_time=0.3)
    for name in r.names:
        np.testing.assert_array_equal(r.data[name], twin.data[name], err_msg=name)
    # by hand: x(0) = 0.5 (sub's parameter connector), u = k (x + 1): explicit Euler, h = 0.1
    x = [0.5]
    for _ in range(3):
        x.append(x[-1] + 0.1 * k * (x[-1] + 1))
    np.testing.assert_allclose(r.data["sub.integ.x"], x, rtol=1e-12)
    # dotted names everywhere: --set, outputs, stop conditions
    r = system_ssp.simulate(ssd, step_size=0.1, stop_time=0.1, parameters={"sub.deeper.g2.k": 10.0},
                            outputs=["sub.integ.x"])
    assert r.names == ["sub.integ.x"] and r.final["sub.deeper.g2.y"] == pytest.approx(10 * (0.5 + 0.1 * 10 * 1.5 + 1))


def test_a_nested_system_connector_that_does_not_exist_is_named(fixture_fmus, tmp_path):
    ssd = nested_system(tmp_path, fixture_fmus)
    ssd.write_text(ssd.read_text().replace('endElement="sub" endConnector="u"', 'endElement="sub" endConnector="uu"'))
    with pytest.raises(SSPError, match=r"SystemStructure.ssd:\d+: nested system 'sub' has no connector 'uu' "
                                       r"\(did you mean 'u'\?\)"):
        system_ssp.System(ssd)


def test_info_and_replace_on_a_nested_system(fixture_fmus, tmp_path, capsys):
    ssd = nested_system(tmp_path, fixture_fmus, "3")
    assert cli.main(["info", str(ssd)]) == 0
    out = capsys.readouterr().out
    assert "component sub.deeper.g2: resources/gain.fmu" in out
    assert f"(bound: 3.0 at {tmp_path / 'root.ssv'}:4)" in out  # the root's binding wins over sub's
    assert f"(bound: 0.5 at {ssd}:11 through system connector sub.x0p)" in out
    # replace inside a nested system: its connections there are checked; the others keep their FMU
    new = tmp_path / "new.ssp"
    assert cli.main(["replace", str(ssd), "sub.deeper.g2", str(fixture_fmus["integrator"]), "--out", str(new)]) == 2
    assert "connection g2.y -> (system).b: y: needs output Real [m]" in capsys.readouterr().err and not new.exists()
    assert cli.main(["replace", str(ssd), "sub.deeper.g2", str(fixture_fmus["gain"]), "--out", str(new)]) == 0
    assert "2 connection" in capsys.readouterr().out
    a = system_ssp.simulate(ssd, step_size=0.1, stop_time=0.3)
    b = system_ssp.simulate(new, step_size=0.1, stop_time=0.3)
    for name in a.names:
        np.testing.assert_array_equal(a.data[name], b.data[name], err_msg=name)
    assert cli.main(["replace", str(ssd), "sub.nothing", str(fixture_fmus["gain"]), "--out", str(new)]) == 2
    assert "no component 'sub.nothing' (components: gain, sub.integ, sub.deeper.g2)" in capsys.readouterr().err


def text_system(tmp_path, fmus):
    """a.text ("prefix" and a's step count) -> b.text_in; b says its length and shouts it."""
    prefix = 'say "hi", '  # a comma and quotes: CSV must quote the field
    bind = ('<ssd:ParameterBinding><ssd:ParameterValues>' + h.ssv_text([("prefix", "String", "PREFIX", None)])
            .split("?>", 1)[1].replace("PREFIX", prefix.replace('"', "&quot;"))
            + "</ssd:ParameterValues></ssd:ParameterBinding>")
    text = h.ssd_text(h.component("a", "text.fmu", bindings=bind) + h.component("b", "text.fmu"),
                      h.connection("a.text", "b.text_in"))
    return h.write_system(tmp_path, fmus, {"text.fmu": "text"}, text), prefix


def test_string_connections_recorded_written_and_printed(fixture_fmus, tmp_path, capsys):
    ssd, prefix = text_system(tmp_path, fixture_fmus)
    r = system_ssp.simulate(ssd, step_size=0.5, stop_time=1.5)
    # by hand: after k steps a.text is prefix + k, b receives it at once (Gauss-Seidel, a before b)
    expected = [f"{prefix}{k}" for k in range(4)]
    assert list(r.data["a.text"]) == expected and list(r.data["b.text_in"]) == expected
    assert list(r.data["b.shout"]) == [e.upper() for e in expected]
    assert list(r.data["b.length"]) == [len(e) for e in expected]
    assert r.final["b.shout"] == 'SAY "HI", 3'
    # CSV: quoted as RFC 4180 says, read back as text
    out = tmp_path / "texts.csv"
    r.write(out)
    import csv
    rows = list(csv.reader(out.open(newline="")))
    assert rows[-1][rows[0].index("b.shout")] == 'SAY "HI", 3'
    assert '"SAY ""HI"", 3"' in out.read_text()
    from system_ssp.master.plotting import read_result
    columns, _ = read_result(out)
    assert list(columns["a.text"]) == expected and list(columns["b.length"]) == [len(e) for e in expected]
    # Parquet: string columns
    import pyarrow.parquet as pq
    r.write(tmp_path / "texts.parquet")
    table = pq.read_table(tmp_path / "texts.parquet")
    assert str(table.schema.field("b.shout").type) == "string"
    assert table.column("a.text").to_pylist() == expected
    # the CLI prints them; a plot of everything leaves the texts out, a plot of a text says why
    assert cli.main(["run", str(ssd), "--step-size", "0.5", "--stop-time", "1.5", "--print-final",
                     "--plot", str(tmp_path / "all.png")]) == 0
    assert """  b.shout = 'SAY "HI", 3'""" in capsys.readouterr().out
    with pytest.raises(SSPError, match=r"signal 'b.shout' holds text \(a String variable\)"):
        r.plot(["b.shout"], out=tmp_path / "text.png")


def test_a_string_connection_with_a_transformation_is_refused(fixture_fmus, tmp_path):
    ssd, _ = text_system(tmp_path, fixture_fmus)
    ssd.write_text(ssd.read_text().replace(
        'endConnector="text_in"></ssd:Connection>',
        'endConnector="text_in"><ssc:LinearTransformation factor="2"/></ssd:Connection>'))
    with pytest.raises(SSPError, match=r"a String connection cannot have a transformation"):
        system_ssp.System(ssd)


def test_several_bindings_on_one_element_the_later_wins(tmp_path):
    """SSP: bindings are applied in document order, so a later one overrides an earlier one; an
    inline set and a file, the second with a prefix."""
    (tmp_path / "resources").mkdir()
    shutil.copy(FMUS / "BouncingBall.fmu", tmp_path / "resources" / "BouncingBall.fmu")
    (tmp_path / "first.ssv").write_text(h.ssv_text([("g", "Real", "-1", None), ("e", "Real", "0.5", None)]))
    (tmp_path / "second.ssv").write_text(h.ssv_text([("g", "Real", "-2", None)]))
    inline = ('<ssd:ParameterBinding><ssd:ParameterValues>'
              + h.ssv_text([("e", "Real", "0.25", None)]).split("?>", 1)[1]
              + "</ssd:ParameterValues></ssd:ParameterBinding>")
    binds = ('<ssd:ParameterBinding source="first.ssv"/>' + inline
             + '<ssd:ParameterBinding source="second.ssv"/>')
    (tmp_path / "SystemStructure.ssd").write_text(h.ssd_text(h.component("ball", "BouncingBall.fmu", bindings=binds)))
    with system_ssp.System(tmp_path / "SystemStructure.ssd") as system:
        params = {var: value for (_, var), value in make_plan(system, system_ssp.RunOptions(
            stop_time=1, step_size=0.1)).params.items()}
    assert params == {"g": -2.0, "e": 0.25}


def test_a_loop_of_system_connectors_is_refused_by_line(fixture_fmus, tmp_path):
    ssd = top_level_connectors_system(tmp_path, fixture_fmus)
    text = ssd.read_text().replace("<ssd:Connectors>", "<ssd:Connectors>" + _real("k2", "parameter"), 1)
    text = text.replace('<ssd:Connection startConnector="k_cref"',
                        '<ssd:Connection startConnector="k_cref" endConnector="k2"/>\n'
                        '<ssd:Connection startConnector="k2" endConnector="k_cref"/>\n'
                        '<ssd:Connection startConnector="k_cref"', 1)
    ssd.write_text(text)
    with pytest.raises(SSPError, match=r"SystemStructure.ssd:\d+: connection (k2 -> k_cref|k_cref -> k2) closes "
                                       r"a loop of system connectors"):
        system_ssp.System(ssd)


def test_a_stop_condition_inside_a_nested_system(fixture_fmus, tmp_path):
    """integ (x' = 1) -> sub.x -> sub.thr.x; sub.thr.done (x >= 0.35) stops the run, named by its
    path, from the caller and from our annotation."""
    sub = ('<ssd:System name="sub"><ssd:Connectors>' + _real("x", "input", "m") + "</ssd:Connectors><ssd:Elements>"
           + h.component("thr", "thr.fmu") + "</ssd:Elements><ssd:Connections>" + _sys_connection("x", "thr.x")
           + "</ssd:Connections></ssd:System>")
    ann = ('<ssd:Annotations><ssc:Annotation type="org.neighbor-cosim.master"><nc:Master '
           'xmlns:nc="https://neighbor-cosim.org/ssp/master"><nc:StopCondition component="sub.thr" connector="done"/>'
           '</nc:Master></ssc:Annotation></ssd:Annotations>')
    values = h.ssv_text([("integ.u", "Real", "1", None), ("sub.thr.threshold", "Real", "0.35", None)])
    bind = '<ssd:ParameterBindings><ssd:ParameterBinding source="root.ssv"/></ssd:ParameterBindings>'
    for name, extra in (("caller", ""), ("annotation", ann)):
        ssd = h.write_system(tmp_path / name, fixture_fmus, {"integ.fmu": "integrator", "thr.fmu": "threshold"},
                             h.ssd_text(h.component("integ", "integ.fmu") + sub, _sys_connection("integ.x", "sub.x"),
                                        system_head=bind, system_extra=extra), extra_files={"root.ssv": values})
        r = system_ssp.simulate(ssd, step_size=0.1, stop_time=2.0, stop_when=["sub.thr.done"] if not extra else None)
        assert r.stop_reason.startswith("stop condition sub.thr.done at t=0.4 s"), r.stop_reason
        assert r.final["sub.thr.x"] == pytest.approx(0.4)
