"""Tests of the co-simulation master (system_ssp) on small fixture FMUs."""
import os
import subprocess
import sys

import numpy as np
import pytest

from master_fixtures import helpers as h
from paths import REPO
import system_ssp
from system_ssp import SimulationError, SSPError

USES = {"integ.fmu": "integrator", "gain.fmu": "gain", "thr.fmu": "threshold"}
INLINE_X0 = ('<ssd:ParameterBinding><ssd:ParameterValues><ssv:ParameterSet version="1.0" name="p"><ssv:Parameters>'
             '<ssv:Parameter name="x0"><ssv:Real value="1"/></ssv:Parameter></ssv:Parameters></ssv:ParameterSet>'
             '</ssd:ParameterValues></ssd:ParameterBinding>')


@pytest.fixture(scope="session")
def fmus(tmp_path_factory):
    return h.build_fixture_fmus(tmp_path_factory.mktemp("master_fmus"))


def loop_system(folder, fmus, experiment='<ssd:DefaultExperiment startTime="0" stopTime="1"/>', gain_bind="",
                system_extra="", extra_files=None, gain_conn="", thr_conn="", units="", system_head=""):
    """integ.x -> gain.u, gain.y -> integ.u (x' = k x, x0 = 1), integ.x -> thr.x."""
    el = (h.component("integ", "integ.fmu", bindings=INLINE_X0)
          + h.component("gain", "gain.fmu", connectors=gain_conn, bindings=gain_bind)
          + h.component("thr", "thr.fmu", connectors=thr_conn))
    co = h.connection("integ.x", "gain.u") + h.connection("gain.y", "integ.u") + h.connection("integ.x", "thr.x")
    return h.write_system(folder, fmus, USES, h.ssd_text(el, co, units=units, experiment=experiment,
                                                         system_extra=system_extra, system_head=system_head),
                          extra_files)


# ---- basic run, time stamps, DefaultExperiment, GS order -----------------------------------
def test_gauss_seidel_run_and_time_stamps(fmus, tmp_path):
    ssd = loop_system(tmp_path, fmus)
    r = system_ssp.simulate(ssd, step_size=0.1)
    assert r.order == ["gain", "integ", "thr"]  # gain feeds integ through feedthrough y(u); x is stateful
    assert r.steps == 10 and r.stop_reason == "reached stop time" and r.stop_time == 1.0
    assert r.data["time"][0] == 0.0 and len(r.data) == 11
    np.testing.assert_allclose(r.data["time"], np.arange(11) * 0.1, rtol=0, atol=1e-15)
    np.testing.assert_allclose(r.data["integ.x"], 1.1 ** np.arange(11), rtol=1e-12)
    assert r.data["integ.x"][0] == 1.0  # start value recorded after initialization
    assert r.data.dtype["thr.done"] == np.bool_ and r.data.dtype["integ.steps"] == np.int64
    assert r.final["integ.x"] == pytest.approx(1.1 ** 10)
    assert r.final["thr.n_out"] == 3


def test_default_experiment_and_overrides(fmus, tmp_path):
    ssd = loop_system(tmp_path, fmus, experiment='<ssd:DefaultExperiment startTime="2" stopTime="2.5"/>')
    r = system_ssp.simulate(ssd, step_size=0.1)
    assert r.data["time"][0] == 2.0 and r.stop_time == 2.5 and r.steps == 5
    r = system_ssp.simulate(ssd, step_size=0.1, stop_time=2.3)
    assert r.steps == 3 and r.stop_time == 2.3
    # last step shortened to hit the stop time exactly
    r = system_ssp.simulate(ssd, step_size=0.2, start_time=0.0, stop_time=0.5)
    assert list(np.round(r.data["time"], 12)) == [0.0, 0.2, 0.4, 0.5]
    with pytest.raises(SSPError, match="no step size"):
        system_ssp.simulate(ssd)


def test_explicit_order_and_validation(fmus, tmp_path):
    # i1.x -> i2.u, both stateful: the default order (SSD order, no feedthrough edges) is i1, i2
    el = h.component("i2", "integ.fmu") + h.component("i1", "integ.fmu")
    ssd = h.write_system(tmp_path, fmus, USES, h.ssd_text(el, h.connection("i1.x", "i2.u")))
    p = {"i1.u": 1.0}
    r = system_ssp.simulate(ssd, step_size=0.1, stop_time=0.3, parameters=p)
    assert r.order == ["i2", "i1"]
    np.testing.assert_allclose(r.data["i2.x"], [0, 0, 0.01, 0.03], atol=1e-15)  # i2 sees x1(t)
    r = system_ssp.simulate(ssd, step_size=0.1, stop_time=0.3, parameters=p, order=["i1", "i2"])
    assert r.order == ["i1", "i2"]
    np.testing.assert_allclose(r.data["i2.x"], [0, 0.01, 0.03, 0.06], atol=1e-15)  # i2 sees x1(t+h)
    with pytest.raises(SSPError, match="missing: i2"):
        system_ssp.simulate(ssd, step_size=0.1, stop_time=1, order=["i1"])
    with pytest.raises(SSPError, match="more than once"):
        system_ssp.simulate(ssd, step_size=0.1, stop_time=1, order=["i1", "i2", "i2"])
    with pytest.raises(SSPError, match="unknown 'i3'"):
        system_ssp.simulate(ssd, step_size=0.1, stop_time=1, order=["i1", "i2", "i3"])


def test_algebraic_loop_refused(fmus, tmp_path):
    el = h.component("g1", "gain.fmu") + h.component("g2", "gain.fmu")
    co = h.connection("g1.y", "g2.u") + h.connection("g2.y", "g1.u")
    ssd = h.write_system(tmp_path, fmus, {"gain.fmu": "gain"}, h.ssd_text(el, co))
    with pytest.raises(SSPError, match="algebraic loop.*g1 -> g2 -> g1"):
        system_ssp.simulate(ssd, step_size=0.1, stop_time=1)
    r = system_ssp.simulate(ssd, step_size=0.1, stop_time=1, algorithm="jacobi")
    assert r.steps == 10


def test_annotation_settings(fmus, tmp_path):
    ann = ('<ssd:Annotations><ssc:Annotation type="org.neighbor-cosim.master">'
           '<nc:Master xmlns:nc="https://neighbor-cosim.org/ssp/master" stepSize="0.1" algorithm="gauss-seidel">'
           '<nc:Order>integ gain thr</nc:Order><nc:StepMultiple component="thr" multiple="2"/>'
           '<nc:StopCondition component="thr" connector="done"/></nc:Master></ssc:Annotation></ssd:Annotations>')
    ssd = loop_system(tmp_path, fmus, system_extra=ann, experiment='<ssd:DefaultExperiment stopTime="10"/>')
    r = system_ssp.simulate(ssd, parameters={"thr.threshold": 1.3})
    assert r.step_size == 0.1 and r.order == ["integ", "gain", "thr"]
    assert r.stop_reason.startswith("stop condition thr.done")
    with system_ssp.System(ssd) as s:
        assert "stepSize=0.1" in s.info()


def test_bad_annotation_content(fmus, tmp_path):
    ann = ('<ssd:Annotations><ssc:Annotation type="org.neighbor-cosim.master">'
           '<nc:Master xmlns:nc="https://neighbor-cosim.org/ssp/master" stepSize="-1"/>'
           '</ssc:Annotation></ssd:Annotations>')
    ssd = loop_system(tmp_path, fmus, system_extra=ann)
    with pytest.raises(SSPError, match=r"SystemStructure.ssd:\d+: nc:Master stepSize must be a positive"):
        system_ssp.System(ssd)


# ---- stop conditions ------------------------------------------------------------------------
def test_stop_condition_time(fmus, tmp_path):
    ssd = loop_system(tmp_path, fmus, experiment='<ssd:DefaultExperiment stopTime="100"/>')
    r = system_ssp.simulate(ssd, step_size=0.1, parameters={"thr.threshold": 2.0}, stop_when=["thr.done"])
    # x_n = 1.1^n >= 2 first at n = 8: the feedthrough flag reflects t+h thanks to the final propagation
    assert r.steps == 8 and r.stop_time == pytest.approx(0.8)
    assert r.stop_reason == "stop condition thr.done at t=0.8 s"
    assert bool(r.data["thr.done"][-1]) and not r.data["thr.done"][:-1].any()
    with pytest.raises(SSPError, match="must be a Boolean"):
        system_ssp.simulate(ssd, step_size=0.1, stop_when=["integ.x"])


# ---- step multiples -------------------------------------------------------------------------
def test_step_multiples(fmus, tmp_path):
    ssd = loop_system(tmp_path, fmus)
    r = system_ssp.simulate(ssd, step_size=0.1, step_multiples={"integ": 5})
    # integ steps at t=0 and t=0.5 with step 0.5
    assert list(r.data["integ.steps"]) == [0, 1, 1, 1, 1, 1, 2, 2, 2, 2, 2]
    assert r.data["integ.x"][5] == pytest.approx(1.5) and r.data["integ.x"][10] == pytest.approx(2.25)
    with pytest.raises(SSPError, match="integer >= 1"):
        system_ssp.simulate(ssd, step_size=0.1, step_multiples={"integ": 0})


# ---- connections: unconnected input, transformation, units ----------------------------------
def test_unconnected_input_keeps_start_value(fmus, tmp_path):
    el = h.component("integ", "integ.fmu", bindings=INLINE_X0) + h.component("thr", "thr.fmu")
    ssd = h.write_system(tmp_path, fmus, USES, h.ssd_text(el, h.connection("integ.x", "thr.x")))
    r = system_ssp.simulate(ssd, step_size=0.1, stop_time=0.5, parameters={"integ.u": 2.0})
    assert np.all(r.data["integ.u"] == 2.0)
    np.testing.assert_allclose(r.data["integ.x"][-1], 2.0)


def test_linear_transformation(fmus, tmp_path):
    el = h.component("integ", "integ.fmu", bindings=INLINE_X0) + h.component("gain", "gain.fmu")
    co = (h.connection("integ.x", "gain.u", '<ssc:LinearTransformation factor="3" offset="0.5"/>'))
    ssd = h.write_system(tmp_path, fmus, USES, h.ssd_text(el, co))
    r = system_ssp.simulate(ssd, step_size=0.1, stop_time=0.2, parameters={"integ.u": 1.0})
    np.testing.assert_allclose(r.data["gain.u"], 3 * r.data["integ.x"] + 0.5)


def test_linear_transformation_written_against_data_flow(fmus, tmp_path):
    el = h.component("integ", "integ.fmu", bindings=INLINE_X0) + h.component("gain", "gain.fmu")
    co = h.connection("gain.u", "integ.x", '<ssc:LinearTransformation factor="2"/>')  # start = input
    ssd = h.write_system(tmp_path, fmus, USES, h.ssd_text(el, co))
    r = system_ssp.simulate(ssd, step_size=0.1, stop_time=0.1)
    np.testing.assert_allclose(r.data["gain.u"], r.data["integ.x"] / 2)


MM = '<ssc:Unit name="mm"><ssc:BaseUnit m="1" factor="0.001"/></ssc:Unit>'


def test_unit_conversion(fmus, tmp_path):
    # gain.y is in m (FMU unit); integ.u declares mm on its SSD connector (the FMU has no unit)
    el = (h.component("integ", "integ.fmu", connectors='<ssd:Connector name="u" kind="input"><ssc:Real unit="mm"/>'
                      '</ssd:Connector>') + h.component("gain", "gain.fmu"))
    co = h.connection("gain.y", "integ.u")
    ssd = h.write_system(tmp_path, fmus, USES, h.ssd_text(el, co, units=MM))
    r = system_ssp.simulate(ssd, step_size=0.1, stop_time=0.1, parameters={"gain.u": 0.25})
    assert r.data["integ.u"][0] == pytest.approx(250.0)


def test_incompatible_units_refused(fmus, tmp_path):
    el = (h.component("integ", "integ.fmu", connectors='<ssd:Connector name="u" kind="input"><ssc:Real unit="s"/>'
                      '</ssd:Connector>') + h.component("gain", "gain.fmu"))
    ssd = h.write_system(tmp_path, fmus, USES, h.ssd_text(el, h.connection("gain.y", "integ.u")))
    with pytest.raises(SSPError, match=r"connection gain.y -> integ.u: incompatible units 'm'.*'s'"):
        system_ssp.System(ssd)


# ---- parameters -------------------------------------------------------------------------------
SSV_UNITS = '<ssc:Unit name="km"><ssc:BaseUnit m="1" factor="1000"/></ssc:Unit>'


def test_ssv_prefix_mapping_and_overrides(fmus, tmp_path):
    files = {
        "params/gain.ssv": h.ssv_text([("k", "Real", "2.0", None), ("bias_km", "Real", "0.001", "km")],
                                      units=SSV_UNITS),
        "params/sys.ssv": h.ssv_text([("threshold", "Real", "5", None), ("n", "Integer", "7", None)]),
        "params/gain.ssm": ('<?xml version="1.0" encoding="UTF-8"?>\n<ssm:ParameterMapping version="1.0" '
                            'xmlns:ssm="http://ssp-standard.org/SSP1/SystemStructureParameterMapping" '
                            'xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon">'
                            '<ssm:MappingEntry source="bias_km" target="b"/>'
                            '<ssm:MappingEntry source="k" target="k"><ssc:LinearTransformation factor="-1"/>'
                            '</ssm:MappingEntry></ssm:ParameterMapping>\n'),
        "extra.ssv": h.ssv_text([("thr.n", "Integer", "9", None)]),
    }
    gain_bind = ('<ssd:ParameterBinding source="params/gain.ssv">'
                 '<ssd:ParameterMapping source="params/gain.ssm"/></ssd:ParameterBinding>')
    sys_bind = ('<ssd:ParameterBindings><ssd:ParameterBinding source="params/sys.ssv" prefix="thr."/>'
                '</ssd:ParameterBindings>')
    ssd = loop_system(tmp_path, fmus, gain_bind=gain_bind, system_head=sys_bind, extra_files=files)
    r = system_ssp.simulate(ssd, step_size=0.1, stop_time=0.1)
    # k = -2 (mapped with factor -1), b = 0.001 km = 1 m, gain.y = -2 * 1 + 1
    assert r.data["gain.y"][0] == pytest.approx(-1.0)
    assert r.final["thr.n_out"] == 7
    r = system_ssp.simulate(ssd, step_size=0.1, stop_time=0.1, parameter_sets=[tmp_path / "extra.ssv"],
                            parameters={"gain.k": 3.0})
    assert r.final["thr.n_out"] == 9
    assert r.data["gain.y"][0] == pytest.approx(4.0)
    # parameter set by name inside an .ssp archive
    ssp = h.pack_ssp(tmp_path, tmp_path.parent / f"{tmp_path.name}.ssp")
    r = system_ssp.simulate(ssp, step_size=0.1, stop_time=0.1, parameter_sets=["extra.ssv"])
    assert r.final["thr.n_out"] == 9


def test_ssv_incompatible_unit(fmus, tmp_path):
    files = {"g.ssv": h.ssv_text([("b", "Real", "1", "s")])}
    ssd = loop_system(tmp_path, fmus, gain_bind='<ssd:ParameterBinding source="g.ssv"/>', extra_files=files)
    with pytest.raises(SSPError, match=r"g.ssv:\d+: gain.b: value in unit 's'.*cannot be converted.*'m'"):
        system_ssp.simulate(ssd, step_size=0.1, stop_time=0.1)


@pytest.mark.parametrize("params, pattern", [
    ({"gian.k": 1.0}, r"unknown component 'gian'.*did you mean 'gain'"),
    ({"gain.kk": 1.0}, r"component 'gain' has no variable 'kk'.*did you mean 'k'"),
    ({"gain.k": "abc"}, r"gain.k: 'abc' is not a valid value: expected a Real"),
    ({"thr.n": 1.5}, r"thr.n: 1.5 is not a valid value: expected an Integer"),
    ({"thr.enabled": 1.5}, r"thr.enabled: 1.5 is not a valid value: expected a Boolean"),
    ({"gain.k": float("nan")}, r"gain.k: nan is not a valid value: expected a finite Real"),
    ({"gain.k": float("inf")}, r"gain.k: inf is not a valid value: expected a finite Real"),
    ({"gain.y": 1.0}, r"gain.y: cannot be set"),
])
def test_bad_parameters(fmus, tmp_path, params, pattern):
    ssd = loop_system(tmp_path, fmus)
    with pytest.raises(SSPError, match=pattern):
        system_ssp.simulate(ssd, step_size=0.1, parameters=params)


def test_typed_parameters_accepted(fmus, tmp_path):
    ssd = loop_system(tmp_path, fmus)
    r = system_ssp.simulate(ssd, step_size=0.1, stop_time=0.1,
                            parameters={"thr.n": "4", "thr.enabled": "false", "gain.label": "x", "gain.k": 2})
    assert r.final["thr.n_out"] == 4 and not r.data["thr.done"].any()


def test_fmu_exception_surfaces(fmus, tmp_path):
    ssd = loop_system(tmp_path, fmus)
    with pytest.raises(SimulationError, match=r"component 'gain'.*k = 5.0 exceeds k_max = 2.0"):
        system_ssp.simulate(ssd, step_size=0.1, parameters={"gain.k": 5.0, "gain.k_max": 2.0})


# ---- files ------------------------------------------------------------------------------------
def test_malformed_ssd(fmus, tmp_path):
    ssd = loop_system(tmp_path, fmus)
    text = ssd.read_text().replace("</ssd:Elements>", "</ssd:Elementz>")
    ssd.write_text(text)
    with pytest.raises(SSPError, match=r"SystemStructure.ssd:\d+: malformed XML"):
        system_ssp.System(ssd)


def test_schema_invalid_ssd(fmus, tmp_path):
    ssd = loop_system(tmp_path, fmus)
    lines = ssd.read_text().splitlines()
    lines.insert(7, '<ssd:Bogus/>')  # line 8, inside ssd:System
    ssd.write_text("\n".join(lines).replace('<ssd:Bogus/>\n<ssd:System', '<ssd:System'))
    text = ssd.read_text().replace('<ssd:System name="root">', '<ssd:System name="root" bogus="1">')
    ssd.write_text(text)
    with pytest.raises(SSPError, match=r"SystemStructure.ssd:\d+: schema violation"):
        system_ssp.System(ssd)


def test_schema_invalid_ssv_names_file_and_line(fmus, tmp_path):
    files = {"g.ssv": h.ssv_text([("k", "Real", "notanumber", None)])}
    ssd = loop_system(tmp_path, fmus, gain_bind='<ssd:ParameterBinding source="g.ssv"/>', extra_files=files)
    with pytest.raises(SSPError, match=r"g.ssv:\d+: schema violation"):
        system_ssp.System(ssd)


def test_missing_fmu(fmus, tmp_path):
    ssd = loop_system(tmp_path, fmus)
    (tmp_path / "resources" / "gain.fmu").unlink()
    with pytest.raises(SSPError, match=r"component 'gain': FMU file not found.*resources/gain.fmu"):
        system_ssp.System(ssd)


def test_ssp_archive_and_csv(fmus, tmp_path):
    folder = tmp_path / "sys"
    loop_system(folder, fmus)
    ssp = h.pack_ssp(folder, tmp_path / "loop.ssp")
    out = tmp_path / "res.csv"
    r = system_ssp.simulate(ssp, step_size=0.1, output_file=out, outputs=["integ.x", "thr.done", "integ.steps"])
    lines = out.read_text().splitlines()
    assert lines[0] == "time,integ.x,thr.done,integ.steps"
    assert len(lines) == 12 and lines[1] == "0.0,1.0,1,0" and lines[2] == "0.1,1.1,1,1"
    assert r.data.dtype.names == ("time", "integ.x", "thr.done", "integ.steps")
    with pytest.raises(SSPError, match="output 'integ.nope'"):
        system_ssp.simulate(ssp, step_size=0.1, outputs=["integ.nope"])


def test_csv_atomic_on_failure(fmus, tmp_path):
    ssd = loop_system(tmp_path, fmus)
    out = tmp_path / "new.csv"
    with pytest.raises(SimulationError):
        system_ssp.simulate(ssd, step_size=0.1, output_file=out, parameters={"gain.k": 5.0, "gain.k_max": 2.0})
    assert not out.exists()
    existing = tmp_path / "old.csv"
    existing.write_text("keep me\n")
    with pytest.raises(SimulationError):
        system_ssp.simulate(ssd, step_size=0.1, output_file=existing, parameters={"gain.k": 5.0, "gain.k_max": 2.0})
    assert existing.read_text() == "keep me\n"
    assert sorted(p.name for p in tmp_path.iterdir() if p.suffix in (".csv", ".tmp")) == ["old.csv"]


def test_system_reuse_and_chaining(fmus, tmp_path):
    ssd = loop_system(tmp_path, fmus)
    with system_ssp.System(ssd) as s:
        r1 = s.run(step_size=0.1, stop_time=0.5)
        r2 = s.run(step_size=0.1, stop_time=0.5, parameters={"integ.x0": r1.final["integ.x"]})
        r3 = s.run(step_size=0.1, stop_time=1.0)
    assert r2.final["integ.x"] == pytest.approx(r3.final["integ.x"], rel=1e-12)


# ---- CLI --------------------------------------------------------------------------------------
def _cli(*args):
    env = dict(os.environ, PYTHONPATH=str(REPO) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    return subprocess.run([sys.executable, "-m", "system_ssp", *map(str, args)], capture_output=True, text=True,
                          env=env, timeout=120)


def test_cli(fmus, tmp_path):
    ssd = loop_system(tmp_path / "sys", fmus)
    out = tmp_path / "r.csv"
    p = _cli("run", ssd, "--step-size", "0.1", "--set", "thr.threshold=2", "--stop-when", "thr.done",
             "--output", out, "--no-progress")
    assert p.returncode == 0, p.stderr
    assert "stop condition thr.done at t=0.8 s" in p.stdout and out.exists()
    p = _cli("run", ssd, "--step-size", "0.1", "--set", "gain.k=abc")
    assert p.returncode == 2 and "gain.k: 'abc' is not a valid value" in p.stderr
    assert "Traceback" not in p.stderr
    p = _cli("run", tmp_path / "nope.ssd", "--step-size", "0.1")
    assert p.returncode == 2 and "nope.ssd: file not found" in p.stderr
    p = _cli("run", ssd, "--step-size", "0.1", "--set", "gain.k=5", "--set", "gain.k_max=2", "--output", out)
    assert p.returncode == 2 and "k = 5.0 exceeds k_max = 2.0" in p.stderr and "Traceback" not in p.stderr
    p = _cli("info", ssd)
    assert p.returncode == 0 and "component gain" in p.stdout and "input  u : Real [m]" in p.stdout
