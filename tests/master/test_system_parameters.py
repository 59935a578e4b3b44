"""System parameters (SSP 1.0 parameter connectors of the system): one value, given once in the
system's own binding, --set or a parameter set, reaches every component parameter it is connected
to; bad names and bad connections are refused with the file and line; `flatten` folds them into
the components' bindings for hosts that do not read them."""
import zipfile

import pytest

import system_ssp
from system_ssp import SSPError
from system_ssp.tools.flatten import flatten_system_parameters
from system_ssp.master.parameters import collect_parameters

MASS_USERS = [("dynamics", "mass"), ("disturbances", "mass"), ("tracking", "mass"), ("estimator", "mass"),
              ("propulsion", "mass0"), ("thrusters", "mass")]


def _values(system, **kw):
    got = collect_parameters(system, **kw)
    return {f"{c.name}.{v}": got[(c.index, v)] for c in system.comps for v in c.vars if (c.index, v) in got}


def test_one_mass_reaches_every_component_that_uses_it(ssp_paths, tmp_path):
    with system_ssp.System(ssp_paths["neighbor_mission_lifetime"]) as s:
        assert [(c.name, v) for c, v, _ in s.parameter_links["spacecraft_mass"]] == MASS_USERS
        default = _values(s)
        assert [default[f"{c}.{v}"] for c, v in MASS_USERS] == [12.0] * len(MASS_USERS)
        heavy = _values(s, parameters={"spacecraft_mass": 14.0})
        assert [heavy[f"{c}.{v}"] for c, v in MASS_USERS] == [14.0] * len(MASS_USERS)
        # a later component value still overrides its own parameter only
        mixed = _values(s, parameters={"spacecraft_mass": 14.0, "tracking.mass": 13.0})
        assert (mixed["dynamics.mass"], mixed["tracking.mass"], mixed["propulsion.mass0"]) == (14.0, 13.0, 14.0)
        # a parameter set with a unit: converted into each component's unit
        ssv = tmp_path / "grams.ssv"
        ssv.write_text('<?xml version="1.0" encoding="UTF-8"?>\n<ssv:ParameterSet xmlns:ssv="http://ssp-standard.org/'
                       'SSP1/SystemStructureParameterValues" version="1.0" name="g"><ssv:Parameters>'
                       '<ssv:Parameter name="spacecraft_mass"><ssv:Real value="13500" unit="g"/></ssv:Parameter>'
                       '</ssv:Parameters><ssv:Units><ssc:Unit xmlns:ssc="http://ssp-standard.org/SSP1/'
                       'SystemStructureCommon" name="g"><ssc:BaseUnit kg="1" factor="0.001"/></ssc:Unit></ssv:Units>'
                       '</ssv:ParameterSet>\n')
        grams = _values(s, parameter_sets=[str(ssv)])
        assert [grams[f"{c}.{v}"] for c, v in MASS_USERS] == [pytest.approx(13.5)] * len(MASS_USERS)
        with pytest.raises(SSPError, match=r"'spacecraft_mas': not a system parameter.*spacecraft_mass"):
            _values(s, parameters={"spacecraft_mas": 14.0})
        with pytest.raises(SSPError, match=r"spacecraft_mass \(system parameter\) -> dynamics.mass"):
            _values(s, parameters={"spacecraft_mass": "heavy"})


def test_a_system_parameter_connected_to_an_output_is_refused(ssp_paths, tmp_path):
    folder = tmp_path / "sys"
    with zipfile.ZipFile(ssp_paths["sun_avoidance_slew"]) as z:
        z.extractall(folder)
    ssd = folder / "SystemStructure.ssd"
    text = ssd.read_text()
    assert 'startConnector="initial_attitude[1]" endElement="dynamics" endConnector="q0[1]"' in text
    ssd.write_text(text.replace('endElement="dynamics" endConnector="q0[1]"',
                                'endElement="dynamics" endConnector="q_BN[1]"'))
    with pytest.raises(SSPError, match=r"SystemStructure.ssd:\d+: connection initial_attitude\[1\] -> dynamics.q_BN"
                                       r"\[1\]: dynamics.q_BN\[1\] has causality output"):
        system_ssp.System(folder).close()


def test_flattened_system_runs_the_same(ssp_paths, tmp_path):
    """The sun-avoidance slew's initial attitude, flattened into the guidance's and the rigid
    body's bindings: the same run, and no system parameter left."""
    flat = tmp_path / "flat.ssp"
    folded = flatten_system_parameters(ssp_paths["sun_avoidance_slew"], flat)
    assert folded["initial_attitude[4]"] == ["guidance.q0[4]", "dynamics.q0[4]"]
    names = ["dynamics.q_BN[1]", "dynamics.omega_BN_B[2]", "tracker.torque_cmd_B[3]"]
    with system_ssp.System(ssp_paths["sun_avoidance_slew"]) as a, system_ssp.System(flat) as b:
        assert not any(b.parameter_links.values())
        ra, rb = (x.run(stop_time=2.0, outputs=names) for x in (a, b))
    for n in names:
        assert list(ra[n]) == list(rb[n])
    with zipfile.ZipFile(flat) as z:
        assert "startElement" in z.read("SystemStructure.ssd").decode()
        assert not [c for c in z.read("SystemStructure.ssd").decode().split("<ssd:Connection ")[1:]
                    if "startElement" not in c]
