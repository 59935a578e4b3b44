"""Diagnostics a user can act on (issue 15, defect 8): each refusal names the file and line,
component or variable, and what is allowed."""
import logging
import re
import shutil
import zipfile

import pytest

from master_fixtures import helpers as h
import system_ssp
from system_ssp import SimulationError, SSPError
from test_master_core import loop_system

NC = 'xmlns:nc="https://neighbor-cosim.org/ssp/master"'


@pytest.fixture(scope="session")
def fmus(tmp_path_factory):
    return h.build_fixture_fmus(tmp_path_factory.mktemp("master_fmus"))


def _edit_model_description(src, dest, edit):
    """Copy FMU `src` to `dest` with its modelDescription.xml passed through `edit(text)`."""
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dest, "w") as zout:
        for item in zin.infolist():
            data = zin.read(item.filename)
            if item.filename == "modelDescription.xml":
                data = edit(data.decode()).encode()
            zout.writestr(item, data)
    return dest


def test_variable_the_code_lacks_is_named(fmus, tmp_path):
    """A model description listing a variable the FMU's code lacks (before: 'fatal at t=0 s:
    (77,)'): the error names the variable and says what is wrong."""
    ghost = ('<ScalarVariable name="ghost" valueReference="77" causality="parameter" variability="fixed">'
             '<Real start="1.0"/></ScalarVariable>')
    def add_ghost(text):
        return text.replace("<ModelVariables>", "<ModelVariables>" + ghost)

    fmus = dict(fmus, gain=_edit_model_description(fmus["gain"], tmp_path / "gain.fmu", add_ghost))
    ssd = loop_system(tmp_path / "sys", fmus)
    with pytest.raises(SimulationError, match=r"component 'gain': setting parameters/start values \(Real\) of .*ghost"
                                              r".* value reference 77 is not a variable of this FMU's code"):
        system_ssp.simulate(ssd, step_size=0.1, stop_time=0.2, parameters={"gain.ghost": 2.0})


def test_changed_guid_is_refused(fmus, tmp_path):
    """An FMU whose model description carries another GUID than its binary was built with."""
    def new_guid(text):
        return re.sub(r'guid="[^"]*"', 'guid="{00000000-0000-0000-0000-000000000000}"', text, count=1)

    fmus = dict(fmus, gain=_edit_model_description(fmus["gain"], tmp_path / "gain.fmu", new_guid))
    ssd = loop_system(tmp_path / "sys", fmus)
    with pytest.raises(SimulationError, match=r"component 'gain': fmi2Instantiate.*GUID.*different builds"):
        system_ssp.simulate(ssd, step_size=0.1, stop_time=0.2)


def test_unit_of_an_unconnected_connector_is_checked(fmus, tmp_path):
    """An unconnected connector's unit must exist and fit its variable (before: ignored)."""
    for unit, pattern in (("kg", r"SystemStructure.ssd:\d+: connector thr.x: incompatible units 'kg'"),
                          ("furlong", r"SystemStructure.ssd:\d+: connector thr.x: unit 'furlong' has no definition")):
        el = h.component("thr", "thr.fmu", connectors=f'<ssd:Connector name="x" kind="input"><ssc:Real unit="{unit}"/>'
                                                      '</ssd:Connector>')
        ssd = h.write_system(tmp_path / unit, fmus, {"thr.fmu": "threshold"}, h.ssd_text(el))
        with pytest.raises(SSPError, match=pattern):
            system_ssp.System(ssd)


def test_connection_to_an_undeclared_connector(fmus, tmp_path):
    """A component that declares connectors must declare the ones it is connected through."""
    ssd = loop_system(tmp_path, fmus, gain_conn='<ssd:Connector name="u" kind="input"><ssc:Real/></ssd:Connector>')
    with pytest.raises(SSPError, match=r"SystemStructure.ssd:\d+: connection gain.y -> integ.u: component 'gain' "
                                       r"declares connectors but not 'y'"):
        system_ssp.System(ssd)


def test_parameter_twice_in_one_parameter_set(fmus, tmp_path):
    twice = tmp_path / "twice.ssv"
    twice.write_text(h.ssv_text([("gain.k", "Real", "1", None), ("gain.b", "Real", "0", None),
                                 ("gain.k", "Real", "2", None)]))
    ssd = loop_system(tmp_path / "sys", fmus)
    with pytest.raises(SSPError, match=r"twice.ssv:5: parameter 'gain.k' is already set on line 3"):
        system_ssp.simulate(ssd, step_size=0.1, stop_time=0.2, parameter_sets=[twice])


def test_explicit_order_through_an_algebraic_loop(fmus, tmp_path):
    """nc:Order cannot make a feedthrough cycle run as Gauss-Seidel (before: accepted silently)."""
    ann = (f'<ssd:Annotations><ssc:Annotation type="org.neighbor-cosim.master"><nc:Master {NC} stepSize="0.1">'
           '<nc:Order>g1 g2</nc:Order></nc:Master></ssc:Annotation></ssd:Annotations>')
    el = h.component("g1", "gain.fmu") + h.component("g2", "gain.fmu")
    co = h.connection("g1.y", "g2.u") + h.connection("g2.y", "g1.u")
    ssd = h.write_system(tmp_path, fmus, {"gain.fmu": "gain"}, h.ssd_text(el, co, system_extra=ann))
    with pytest.raises(SSPError, match=r"SystemStructure.ssd:\d+: nc:Order \['g1', 'g2'\]: the components form an "
                                       r"algebraic loop .* g1 -> g2 -> g1"):
        system_ssp.simulate(ssd, stop_time=1)
    with pytest.raises(SSPError, match=r"component order \['g2', 'g1'\]: the components form an algebraic loop"):
        system_ssp.simulate(ssd, stop_time=1, order=["g2", "g1"])
    assert system_ssp.simulate(ssd, stop_time=1, algorithm="jacobi").steps == 10


def test_step_count_limit(fmus, tmp_path):
    """A step size typed orders of magnitude too small (before: MemoryError ... 834 GiB)."""
    ssd = loop_system(tmp_path, fmus)
    with pytest.raises(SSPError, match=r"1000 s in steps of 1e-08 s are 100,000,000,000 communication steps, more "
                                       r"than the 2,000,000,000 a run may take"):
        system_ssp.simulate(ssd, step_size=1e-8, stop_time=1000)


def test_parameter_set_in_both_places_says_which(fmus, tmp_path, monkeypatch, caplog):
    """A relative --ssv path found in the working directory and inside the .ssp: the working
    directory's is used and a warning names both."""
    folder = tmp_path / "sys"
    loop_system(folder, fmus, extra_files={"parameters/p.ssv": h.ssv_text([("gain.k", "Real", "2", None)])})
    ssp = h.pack_ssp(folder, tmp_path / "loop.ssp")
    here = tmp_path / "work"
    (here / "parameters").mkdir(parents=True)
    (here / "parameters" / "p.ssv").write_text(h.ssv_text([("gain.k", "Real", "3", None)]))
    monkeypatch.chdir(here)
    with caplog.at_level(logging.WARNING, logger="system_ssp"):
        r = system_ssp.simulate(ssp, step_size=0.1, stop_time=0.1, parameter_sets=["parameters/p.ssv"])
    assert r.final["gain.y"] == pytest.approx(3.0 * r.final["gain.u"])
    assert any("parameter set 'parameters/p.ssv': using" in m and str(here) in m and "loop.ssp" in m
               for m in caplog.messages)
    shutil.rmtree(here / "parameters")
    caplog.clear()
    r = system_ssp.simulate(ssp, step_size=0.1, stop_time=0.1, parameter_sets=["parameters/p.ssv"])
    assert r.final["gain.y"] == pytest.approx(2.0 * r.final["gain.u"]) and not caplog.messages
