"""Swapping a component's fidelity as one checked operation (issue 14): `replace` and `compare`,
the interface families, `info` on FMUs and systems."""
import json
import re
import subprocess
import sys
import zipfile

import numpy as np
import pytest

from components.core.constants import YEAR
from paths import REPO
import system_ssp
from system_ssp.tools.replace import ReplaceRefused, replace_component
from system_ssp.ssp.interface import FmuInterface, compare, describe_fmu
from system_ssp.systems import PARAMETERS_DIR

# Members of a family replace each other: the same inputs and outputs (fidelity-specific
# parameters may differ). (family, [FMU names], [(system, component) that hold a member])
FAMILIES = [
    ("orbit", ["Orbit", "OrbitAveraged"], [("deorbit", "orbit"), ("deorbit_lifetime", "orbit")]),
    ("RCS attitude controller", ["DetumbleController", "SlewController", "TrackingController"],
     [("detumble", "detumble"), ("slew", "slew")]),
    ("RCS thrusters", ["RcsThrusters", "RcsThrusterSet"], [("detumble", "thrusters"), ("slew", "thrusters")]),
    ("magnetic field", ["MagneticField", "MagneticFieldIgrf"], [("acs_modes", "field"), ("neighbor_mission", "field")]),
]
# Connectors a family member may have beyond the family's (its own outputs; the tracking law's
# desired-attitude signals)
EXTRAS = {"attitude_error", "pointing_error", "sliding_vector[1]", "sliding_vector[2]", "sliding_vector[3]",
          "axial_firing", "force_B[1]", "force_B[2]", "force_B[3]", "axial_off_time",  # the thruster set's burn
          # torque, net force and off-pulsing
          # the tracking law's boundary layer sized for the estimate: the knowledge it reads, the e it uses
          "sigma_attitude_B[1]", "sigma_attitude_B[2]", "sigma_attitude_B[3]",
          "boundary_layer[1]", "boundary_layer[2]", "boundary_layer[3]",
          # the thruster set's stuck-thruster detection: the gyro's rates it reads, what it closed
          "omega_meas_B[1]", "omega_meas_B[2]", "omega_meas_B[3]", "disabled_mask", "fault_time",
          # the thruster set's centre of mass following the tank, its force beyond the propulsion's for the orbit
          "propellant_used", "impulse_B[1]", "impulse_B[2]", "impulse_B[3]"}


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "system_ssp", *map(str, args)], capture_output=True, text=True,
                          timeout=300, cwd=REPO)


def test_cowell_replaced_by_the_averaged_orbit(ssp_paths, fmu_paths, tmp_path):
    """The de-orbit system's Cowell orbit swapped for the orbit-averaged one: it validates, runs,
    and its 420 km lifetime with the burn is the averaged model's (the shipped deorbit_lifetime
    system, within 2 %), within the documented Cowell-vs-averaged difference (docs/models/
    orbit.md: 1.31 vs 1.49 years, under 20 %)."""
    out = tmp_path / "deorbit_averaged.ssp"
    report = replace_component(ssp_paths["deorbit"], "orbit", fmu_paths["OrbitAveraged"], out)
    assert report.connections == 4 and not report.dropped and not report.conversions
    assert set(report.new_parameters) == {"j2", "quadrature_nodes", "max_step", "max_da_step", "thrust_step"}
    scenario = [str(PARAMETERS_DIR / "deorbit_420km.ssv")]
    with system_ssp.System(out) as system:
        assert system.by_name["orbit"].md.modelName == "OrbitAveraged"
        swapped = system.run(parameter_sets=scenario, outputs=["orbit.sma"])
    with system_ssp.System(ssp_paths["deorbit_lifetime"]) as system:
        shipped = system.run(parameter_sets=scenario, outputs=["orbit.sma"])
    years = swapped.stop_time / YEAR
    assert swapped.stop_reason.startswith("stop condition orbit.reentered")
    assert years == pytest.approx(shipped.stop_time / YEAR, rel=0.02)
    assert abs(years - 1.31) / 1.31 < 0.20
    with zipfile.ZipFile(out) as z:
        names = z.namelist()
    assert "resources/OrbitAveraged.fmu" in names and "resources/Orbit.fmu" not in names


def test_refused_replace_lists_every_mismatch_and_writes_nothing(ssp_paths, fmu_paths, tmp_path):
    out = tmp_path / "x.ssp"
    with pytest.raises(ReplaceRefused) as err:
        replace_component(ssp_paths["detumble"], "dynamics", fmu_paths["Propulsion"], out)
    names = {m[1] for m in err.value.mismatches}
    assert {"torque_B[1]", "omega_BN_B[1]", "omega_dot_BN_B[3]", "q0[1]"} <= names
    text = str(err.value)
    assert "Propulsion.fmu cannot replace dynamics (RigidBody.fmu)" in text and "nothing written" in text
    assert re.search(r"connection detumble\.torque_cmd_B\[1\] -> dynamics\.torque_B\[1\]|"
                     r"connection thrusters\.\S+ -> dynamics\.torque_B\[1\]: torque_B\[1\]: needs input Real \[N.m\], "
                     r"Propulsion.fmu has no such variable", text)
    assert not out.exists() and list(tmp_path.iterdir()) == []
    # on the command line: exit 2, every mismatch listed, nothing written
    p = _cli("replace", ssp_paths["detumble"], "dynamics", fmu_paths["Propulsion"], "--out", out)
    assert p.returncode == 2 and p.stderr.count("no such variable") >= 10 and not out.exists()


def test_bound_parameters_the_new_fmu_lacks(ssp_paths, fmu_paths, tmp_path):
    """Refused unless --drop-unmatched; then left out, the rest rewritten into one binding."""
    out = tmp_path / "x.ssp"
    with pytest.raises(ReplaceRefused) as err:
        replace_component(ssp_paths["slew"], "slew", fmu_paths["DetumbleController"], out)
    why = {m[1]: m[3] for m in err.value.mismatches}
    assert "no such variable" in why["q_d[1]"] and "unit N.m does not convert to N.m.s" in why["Kp[1]"]
    assert not out.exists()
    p = _cli("replace", ssp_paths["slew"], "slew", fmu_paths["DetumbleController"], "--out", out, "--drop-unmatched")
    assert p.returncode == 0, p.stderr
    assert "dropped parameter q_d[1]" in p.stdout and "parameters/slew.replaced.ssv" in p.stdout
    with zipfile.ZipFile(out) as z:
        kept = z.read("parameters/slew.replaced.ssv").decode()
    assert 'name="omega_tol[1]"' in kept and "Kp" not in kept and "q_d" not in kept
    with system_ssp.System(out) as system:
        assert system.run(stop_time=0.15).steps >= 0


def _with_unit(src, dest, variable, unit, base):
    """A copy of FMU `src` whose model description gives `variable` the unit `unit`, defined by
    the BaseUnit attributes `base`."""
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dest, "w") as zout:
        for item in zin.infolist():
            data = zin.read(item.filename)
            if item.filename == "modelDescription.xml":
                text = data.decode()
                text = re.sub(rf'(<ScalarVariable name="{re.escape(variable)}"[^>]*>\s*<Real[^>]*?)unit="[^"]*"',
                              rf'\1unit="{unit}"', text, count=1)
                if f'<Unit name="{unit}"' not in text:
                    text = text.replace("<UnitDefinitions>", f'<UnitDefinitions><Unit name="{unit}"><BaseUnit {base}/>'
                                        '</Unit>', 1)
                data = text.encode()
            zout.writestr(item, data)
    return dest


def test_unit_conversion_written_into_the_connection(ssp_paths, fmu_paths, tmp_path):
    """A replacement whose input takes km where the old one took m: the connection gets a
    LinearTransformation (x 0.001) with suppressUnitConversion, so every host feeds the same
    physical value; the run equals the original."""
    km = _with_unit(fmu_paths["RcsThrusters"], tmp_path / "RcsThrustersKm.fmu", "torque_cmd_B[1]", "km",
                    'm="1" factor="1000.0"')
    with pytest.raises(ReplaceRefused, match=r"torque_cmd_B\[1\]: needs unit N.m, RcsThrustersKm.fmu has unit km "
                                             r"\(not convertible\)"):
        replace_component(ssp_paths["detumble"], "thrusters", km, tmp_path / "no.ssp")
    knm = _with_unit(fmu_paths["RcsThrusters"], tmp_path / "RcsThrustersKnm.fmu", "torque_cmd_B[1]", "kN.m",
                     'kg="1" m="2" s="-2" factor="1000.0"')
    out = tmp_path / "x.ssp"
    report = replace_component(ssp_paths["detumble"], "thrusters", knm, out)
    assert report.conversions == [("connection detumble.torque_cmd_B[1] -> thrusters.torque_cmd_B[1]",
                                   pytest.approx(1e-3), 0.0)]
    with zipfile.ZipFile(out) as z:
        ssd = z.read("SystemStructure.ssd").decode()
    assert re.search(r'<ssd:Connection startElement="detumble" startConnector="torque_cmd_B\[1\]" '
                     r'endElement="thrusters" endConnector="torque_cmd_B\[1\]" suppressUnitConversion="true">\s*'
                     r'<ssc:LinearTransformation factor="0.001" offset="0.0"/>', ssd)
    with system_ssp.System(out) as system:
        link = next(lk for lk in system.links if lk.dst_var == "torque_cmd_B[1]")
        assert link.factor == pytest.approx(1e-3)
        swapped = system.run(stop_time=0.3, outputs=["thrusters.torque_cmd_B[1]", "detumble.torque_cmd_B[1]"])
    np.testing.assert_allclose(swapped["thrusters.torque_cmd_B[1]"], swapped["detumble.torque_cmd_B[1]"] * 1e-3)


def test_family_members_share_their_interface(fmu_paths):
    for family, members, _ in FAMILIES:
        first = FmuInterface.read(fmu_paths[members[0]])
        for other in members[1:]:
            diffs = [d for d in compare(first, FmuInterface.read(fmu_paths[other]))
                     if "parameter" not in (d.a or "") + (d.b or "") and d.name not in EXTRAS
                     and not d.name.startswith("q_d")]
            assert diffs == [], f"{family}: {members[0]} vs {other}: {diffs}"


@pytest.mark.parametrize("family, members, holders", FAMILIES, ids=[f[0] for f in FAMILIES])
def test_every_family_swap_runs(ssp_paths, fmu_paths, tmp_path, family, members, holders):
    """Each member replaced by each other member in each system that holds one, then run."""
    for system_name, component in holders:
        with system_ssp.System(ssp_paths[system_name]) as system:
            current = system.by_name[component].md.modelName
        for member in members:
            if member == current:
                continue
            out = tmp_path / f"{system_name}_{member}.ssp"
            replace_component(ssp_paths[system_name], component, fmu_paths[member], out, drop_unmatched=True)
            with system_ssp.System(out) as system:
                assert system.by_name[component].md.modelName == member
                r = system.run(stop_time=3.0)
                assert r.stop_time <= 3.0 and len(r.data) >= 1


def test_compare_command(fmu_paths):
    p = _cli("compare", fmu_paths["Orbit"], fmu_paths["OrbitAveraged"])
    assert p.returncode == 0
    assert re.search(r"zonal_degree\s+A: parameter Integer\s+B: -\s+\(only in A\)", p.stdout)
    assert "10 difference(s)" in p.stdout and "F_thrust_B" not in p.stdout
    p = _cli("compare", fmu_paths["Orbit"], fmu_paths["OrbitAveraged"], "--json")
    assert {d["name"] for d in json.loads(p.stdout)} == {"zonal_degree", "j2", "quadrature_nodes", "max_step",
                                                          "max_da_step", "thrust_step", "gravity_degree",
                                                          "gravity_order", "sun_gravity", "moon_gravity"}


def test_info_lists_every_parameter_of_every_fmu(fmu_paths):
    """Including the ones no system binds (before: Orbit's f107, drag, zonal_degree were invisible)."""
    for name, path in fmu_paths.items():
        fmu = FmuInterface.read(path)
        text = describe_fmu(fmu)
        for v in fmu.variables.values():
            if v.causality in ("parameter", "input", "output"):
                assert f"  {v.name} : {v.type}" in text, (name, v.name)
    text = describe_fmu(FmuInterface.read(fmu_paths["Orbit"]))
    assert re.search(r"zonal_degree : Integer = \d+ .*\(not bound: start value\)", text)
    p = _cli("info", fmu_paths["Orbit"], "--json")
    data = json.loads(p.stdout)
    assert p.returncode == 0 and {"f107", "drag", "zonal_degree"} <= {v["name"] for v in data["variables"]}


def test_info_on_a_system_marks_bound_parameters(ssp_paths):
    p = _cli("info", ssp_paths["deorbit"])
    assert p.returncode == 0
    assert re.search(r"param  Cd : Real \[1\] = .*\(bound: 2\.2 at \S*deorbit_orbit\.ssv:\d+\)", p.stdout)
    assert re.search(r"param  zonal_degree : Integer .*\(not bound: start value\)", p.stdout)
    data = json.loads(_cli("info", ssp_paths["deorbit"], "--json").stdout)
    orbit = next(c for c in data["components"] if c["name"] == "orbit")
    cd = next(v for v in orbit["variables"] if v["name"] == "Cd")
    assert cd["value"] == 2.2 and "deorbit_orbit.ssv" in cd["bound"]
    assert [c["name"] for c in data["components"]] == ["propulsion", "orbit"]  # no decorative atmosphere
