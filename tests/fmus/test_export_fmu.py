"""`neighbor-cosim export-fmu`: a system as one FMU, run in the hosts users have (FMPy, fmusim,
libcosim, ecos; fmusim also on a simulated user machine with only CPython and numpy), against
our master's run of the system at the same step.

What "the same" means: the container gives the embedded FMUs the calls and values of our
master's Gauss-Seidel step, so the states, and the outputs of the component stepped last, are
equal bit for bit at every communication point, and so is every output without direct
feedthrough. The direct-feedthrough outputs of a component stepped earlier are, in the
container, those it computed in the step; our master refreshes them after the step (at t + h),
so there they are one row ahead: the container's row k + 1 is our master's row k, bit for bit
(docs/compose.md)."""
import json
import shutil
import subprocess
import sys
import zipfile

from fmpy.validation import validate_fmu
import fmpy
from lxml import etree
import numpy as np
import pytest

import system_ssp
from system_ssp import cli
from system_ssp.tools.export_fmu import export_fmu

# system: (stop time, the component stepped last, the components stepped before it, step). The
# de-orbit (the burn and the orbit to re-entry) runs without its nc:Schedule, at its 1 h step: an
# exported FMU steps at one fixed step (our master with schedule=False does the same).
CASES = {"detumble": (9.96, "dynamics", ("detumble", "thrusters"), 0.015),
         "slew": (30.0, "dynamics", ("slew", "thrusters"), 0.015),
         "deorbit": (6 * 3600.0, "orbit", ("propulsion",), 3600.0)}


@pytest.fixture(scope="module")
def exported(ssp_paths, tmp_path_factory):
    out = {}
    folder = tmp_path_factory.mktemp("exported")
    for name in CASES:
        for fmi in (2, 3):
            path = folder / f"{name}_fmi{fmi}.fmu"
            export_fmu(ssp_paths[name], path, fmi)
            out[name, fmi] = path
    return out


@pytest.fixture(scope="module")
def master_runs(ssp_paths):
    runs = {}
    for name, (stop, _, _, _) in CASES.items():
        with system_ssp.System(ssp_paths[name]) as s:
            result = s.run(stop_time=stop, schedule=False)
            # the outputs our master refreshes after a step: those with direct feedthrough
            result.feedthrough = {f"{c.name}.{out}" for c in s.comps for out, deps in c.deps.items()
                                  if deps is None or deps}
        runs[name] = result
    return runs


def assert_equal_to_master(name, columns, master, rtol=0.0):
    """`columns`: {component.variable: values per communication point} from a host; `rtol` for
    a host that writes fewer digits than a double needs (fmusim's CSV: 16)."""
    stop, last, earlier, _ = CASES[name]
    compared = 0
    feedthrough = getattr(master, "feedthrough", set())
    for signal, values in columns.items():
        if signal not in master.names:
            continue
        ours = np.asarray(master.data[signal], dtype=float)
        got = np.asarray(values, dtype=float)[:len(ours)]
        assert len(got) == len(ours), signal
        comp = signal.split(".", 1)[0]
        if comp != last and signal in feedthrough:
            assert comp in earlier
            got, ours = got[1:], ours[:-1]
        # every row but the last bit for bit; a host ends on a last step of its own (stop - t,
        # its t a sum of steps), which can differ from ours (stop - n h) in the last bit
        if rtol:
            np.testing.assert_allclose(got[:-1], ours[:-1], rtol=rtol, atol=1e-300, err_msg=signal)
        else:
            np.testing.assert_array_equal(got[:-1], ours[:-1], err_msg=signal)
        np.testing.assert_allclose(got[-1], ours[-1], rtol=1e-12, atol=1e-15, err_msg=signal)
        compared += 1
    assert compared >= min(20, len(columns))


def test_the_exported_fmus_are_valid_with_units_descriptions_and_dependencies(exported):
    for (name, _fmi), path in exported.items():
        assert validate_fmu(str(path)) == [], path
        md = fmpy.read_model_description(str(path))
        variables = {v.name: v for v in md.modelVariables}
        last = CASES[name][1]
        signal, unit, about = {"dynamics": ("dynamics.omega_BN_B[1]", "rad/s", "Angular velocity"),
                               "orbit": ("orbit.r_BN_N[1]", "m", "Spacecraft position")}[last]
        assert variables[signal].causality == "output" and variables[signal].unit == unit
        assert about in variables[signal].description
        assert unit in {u.name for u in md.unitDefinitions}
        assert all(not v.dependencies for v in md.outputs)  # declared: no direct feedthrough
        if name == "detumble":  # the parameters, their starts the values the system binds
            assert variables["dynamics.omega0[1]"].causality == "parameter"
            assert float(variables["dynamics.omega0[1]"].start) == 0.17453292519943295
            assert variables["dynamics.omega0[1]"].unit == "rad/s" and variables["dynamics.integrator"].start == "euler"
        assert md.description.startswith(f"{name}: the system") and "gauss-seidel" in md.description


def test_the_exported_fmus_equal_our_master_in_fmpy(exported, master_runs, ssp_paths):
    for (name, _fmi), path in exported.items():
        stop, _, _, step = CASES[name]
        r = fmpy.simulate_fmu(str(path), stop_time=stop, output_interval=step)
        assert_equal_to_master(name, {n: r[n] for n in r.dtype.names[1:]}, master_runs[name])
    # a parameter the host sets: as --set in our master
    r = fmpy.simulate_fmu(str(exported["detumble", 2]), stop_time=0.3, output_interval=0.015,
                          start_values={"dynamics.omega0[2]": 0.05})
    ours = system_ssp.simulate(ssp_paths["detumble"], stop_time=0.3, parameters={"dynamics.omega0[2]": 0.05})
    np.testing.assert_array_equal(r["dynamics.omega_BN_B[2]"], ours.data["dynamics.omega_BN_B[2]"])


def test_the_exported_fmus_equal_our_master_in_fmusim_here_and_on_a_user_machine(exported, master_runs, fmusim,
                                                                                  user_machine, tmp_path):
    import fmusim_host
    from test_target_machines import _user_python
    from user_machine import on_user_machine, targets

    target = targets()[0]
    target_id, bin_dir, _, _, numpy_dir = _user_python(target)
    for (name, _fmi), path in exported.items():
        stop, _, _, step = CASES[name]
        fmu = tmp_path / path.name  # outside the checkout: the user's machine does not have it
        shutil.copy(path, fmu)
        here, there = tmp_path / f"{path.stem}_here.csv", tmp_path / f"{path.stem}_user.csv"
        proc = fmusim_host.run(fmusim, fmu, here, stop, step)
        assert proc.returncode == 0, proc.stderr[-2000:]
        columns = fmusim_host.read(here)
        if name != "deorbit":  # the orbit's numbers follow the user's numpy in the last digits
            proc = on_user_machine(fmusim_host.command(fmusim, fmu, there, stop, step), [bin_dir], str(numpy_dir))
            assert proc.returncode == 0, f"{target_id}: {proc.stdout[-2000:]}\n{proc.stderr[-2000:]}"
            assert fmusim_host.read(there).keys() == columns.keys()
            for base, values in fmusim_host.read(there).items():  # the user's machine: as here, digit for digit
                assert values.tolist() == columns[base].tolist(), base
        flat = {}
        for base, values in columns.items():
            flat.update({base: values[:, 0]} if values.shape[1] == 1 else
                        {f"{base}[{k + 1}]": values[:, k] for k in range(values.shape[1])})
        assert_equal_to_master(name, flat, master_runs[name], rtol=1e-15)


LIBCOSIM_ONE_FMU = r"""
import json, sys
from libcosimpy.CosimExecution import CosimExecution
from libcosimpy.CosimSlave import CosimLocalSlave
from libcosimpy.CosimObserver import CosimObserver
from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
log_output_level(CosimLogLevel.WARNING)
fmu, step_ns, n, names = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), json.loads(sys.argv[4])
ex = CosimExecution.from_step_size(step_size=step_ns)
i = ex.add_local_slave(CosimLocalSlave(fmu_path=fmu, instance_name="system"))
obs = CosimObserver.create_last_value()
ex.add_observer(obs)
refs = {v.name.decode(): v.reference for v in ex.slave_variables(i)}
rows = []
for _ in range(n):
    ex.step(1)
    rows.append([obs.last_real_values(i, [refs[name]])[0] for name in names])
print("ROWS " + json.dumps(rows))
"""


@pytest.mark.parametrize("name", ["detumble", "slew"])
def test_the_exported_maneuvers_equal_our_master_in_libcosim(exported, master_runs, name):
    pytest.importorskip("libcosimpy", reason="libcosimpy is not installed (pip install libcosimpy)")
    master = master_runs[name]
    names = [f"dynamics.omega_BN_B[{k}]" for k in (1, 2, 3)] + [f"{name}.torque_cmd_B[{k}]" for k in (1, 2, 3)]
    n = len(master.data) - 1
    proc = subprocess.run([sys.executable, "-c", LIBCOSIM_ONE_FMU, str(exported[name, 2]),
                           str(15_000_000), str(n), json.dumps(names)], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    rows = np.array(json.loads(next(line[5:] for line in proc.stdout.splitlines() if line.startswith("ROWS "))))
    # libcosim's observer sees the values after each step: our master's rows 1 ..
    columns = {name: np.concatenate([[master.data[name][0]], rows[:, k]]) for k, name in enumerate(names)}
    assert_equal_to_master(name, columns, master)


@pytest.mark.parametrize("name", ["detumble", "slew"])
def test_the_exported_maneuvers_run_in_ecos_on_a_user_machine(exported, master_runs, user_machine, tmp_path, name):
    from test_compat import ECOS_TOLERANCE, _user_python
    import importlib.util
    from user_machine import numpy_for, on_user_machine

    spec = importlib.util.find_spec("ecospy")
    if spec is None:
        pytest.skip("ecospy is not installed (pip install ecospy)")
    binary = tmp_path / "ecos"
    shutil.copyfile(spec.submodule_search_locations[0] + "/binaries/ecos", binary)
    binary.chmod(0o755)
    if subprocess.run([str(binary), "--version"], capture_output=True).returncode != 0:
        pytest.skip("the ecos command does not start: apt install libtbb12")
    target_id, _, bin_dir, installer = _user_python()
    numpy_dir = numpy_for(target_id, installer, int(target_id.rsplit(".", 1)[1]))
    work = tmp_path / "run"
    work.mkdir()
    shutil.copy(exported[name, 2], work / f"{name}.fmu")
    proc = on_user_machine(["sh", "-c", f'cd "{work}" && exec "$@"', "sh", str(binary), "simulate", "--path",
                            f"{name}.fmu", "--stopTime", repr(CASES[name][0]), "--stepSize", "0.015", "--noParallel"],
                           [bin_dir], str(numpy_dir))
    assert proc.returncode == 0, f"{proc.stdout[-2000:]}\n{proc.stderr[-2000:]}"
    from system_ssp.tools import compat
    got = compat.read_csv(work / f"{name}.csv", separator=", ")
    got = {name.split("::", 1)[-1].rsplit("[", 1)[0]: v for name, v in got.items()}  # instance::x[1][REAL]
    ours = master_runs[name].data
    for k in (1, 2, 3):
        column = np.asarray(got[f"dynamics.omega_BN_B[{k}]"], float)
        assert len(column) >= len(ours) - 1
        n = min(len(column), len(ours))  # ecos writes its CSV with 6 decimals
        np.testing.assert_allclose(column[:n], ours[f"dynamics.omega_BN_B[{k}]"][:n], atol=ECOS_TOLERANCE[0],
                                   rtol=ECOS_TOLERANCE[1])


def test_export_fmu_names_what_a_container_cannot_do(ssp_paths, tmp_path, capsys):
    out = tmp_path / "x.fmu"
    assert cli.main(["export-fmu", "detumble", "--out", str(out), "--outputs",
                     "dynamics.omega_BN_B,detumble.done"]) == 0
    said = capsys.readouterr().out
    assert "4 outputs" in said and "stop conditions (detumble.done" in said
    with zipfile.ZipFile(out) as z:
        md = etree.fromstring(z.read("modelDescription.xml"))
    assert [v.get("name") for v in md.iter("ScalarVariable") if v.get("causality") == "output"] == [
        "dynamics.omega_BN_B[1]", "dynamics.omega_BN_B[2]", "dynamics.omega_BN_B[3]", "detumble.done"]
    assert cli.main(["export-fmu", "detumble", "--out", str(tmp_path / "y.fmu"), "--inputs",
                     "detumble.omega_BN_B"]) == 2
    assert "a connection of the system feeds it" in capsys.readouterr().err
    assert cli.main(["export-fmu", "detumble", "--out", str(tmp_path / "z.fmu"), "--outputs", "dynamics.omega"]) == 2
    assert "did you mean" in capsys.readouterr().err and not (tmp_path / "z.fmu").exists()


def test_an_unconnected_input_the_host_sets(ssp_paths, tmp_path):
    out = tmp_path / "with_input.fmu"
    done = export_fmu(ssp_paths["detumble"], out, 2, outputs=["dynamics.omega_BN_B"],
                      inputs=["dynamics.wheel_torque_B"])
    assert done["inputs"] == [f"dynamics.wheel_torque_B[{k}]" for k in (1, 2, 3)]
    md = fmpy.read_model_description(str(out))
    torque = next(v for v in md.modelVariables if v.name == "dynamics.wheel_torque_B[3]")
    assert torque.causality == "input" and torque.unit == "N.m"
    r = fmpy.simulate_fmu(str(out), stop_time=1.5, output_interval=0.015,
                          start_values={"dynamics.wheel_torque_B[3]": 0.01})
    ours = system_ssp.simulate(ssp_paths["detumble"], stop_time=1.5, parameters={"dynamics.wheel_torque_B[3]": 0.01})
    free = system_ssp.simulate(ssp_paths["detumble"], stop_time=1.5)
    assert_equal_to_master("detumble", {"dynamics.omega_BN_B[3]": r["dynamics.omega_BN_B[3]"]}, ours)
    assert ours.final["dynamics.omega_BN_B[3]"] != free.final["dynamics.omega_BN_B[3]"]
