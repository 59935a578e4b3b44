"""Every FMU in hosts other than our master: a C program with no Python in it (dlopen, the FMI
calls, unload, load again; on a user's machine: test_target_machines.py), FMPy in a fresh virtual
environment that has only fmpy and numpy, and a plain Python process that runs several systems
one after another and exits normally."""
import json
import os
from pathlib import Path
import re
import shutil
import subprocess
import sys
import sysconfig
import zipfile

import fmpy
from fmpy.fmi2 import FMU2Slave
import numpy as np
import pytest


STEP, STEPS = 0.015, 3
# A C host's environment: nothing that points at a Python.
CLEAN_ENV = {"PATH": "/usr/bin:/bin", "HOME": os.environ.get("HOME", "/tmp")}


def plan(path):
    """(guid, model identifier, [host options], [(real output, vr)]): set the first Real parameter
    to its start value, read the first three Real outputs."""
    md = fmpy.read_model_description(str(path))
    params = [v for v in md.modelVariables if v.causality == "parameter" and v.type == "Real"]
    outputs = [v for v in md.modelVariables if v.causality == "output" and v.type == "Real"][:3]
    opts = []
    if params:
        opts += ["--set-real", str(params[0].valueReference), repr(float(params[0].start))]
    for v in outputs:
        opts += ["--get-real", str(v.valueReference)]
    return md.guid, md.coSimulation.modelIdentifier, opts, outputs


def extract(path, folder):
    with zipfile.ZipFile(path) as z:
        z.extractall(folder)
    return folder


def fmpy_values(path, folder, outputs, params_opts):
    """The same calls through FMPy in this process: the values the C host must read."""
    md = fmpy.read_model_description(str(path))
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=str(folder), modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName="fmpy")
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    if params_opts:
        fmu.setReal([int(params_opts[1])], [float(params_opts[2])])
    fmu.exitInitializationMode()
    for k in range(STEPS):
        fmu.doStep(k * STEP, STEP)
    values = fmu.getReal([v.valueReference for v in outputs]) if outputs else []
    fmu.terminate()
    fmu.freeInstance()
    return values


def run_host(c_host, folder, model, guid, opts, extra=(), env=None):
    return subprocess.run([str(c_host), str(folder), model, guid, *opts, "--steps", str(STEPS), "--step", str(STEP),
                           *extra], capture_output=True, text=True, timeout=300, env=env or CLEAN_ENV)


def test_every_fmu_runs_in_a_c_host_without_python(c_host, fmu_paths, tmp_path):
    """instantiate, set a parameter, initialize, step, get, terminate, free, unload; twice; the
    values equal FMPy's for the same calls."""
    for name, path in sorted(fmu_paths.items()):
        folder = extract(path, tmp_path / name)
        guid, model, opts, outputs = plan(path)
        proc = run_host(c_host, folder, model, guid, opts)
        assert proc.returncode == 0, f"{name}:\n{proc.stdout[-3000:]}\n{proc.stderr[-2000:]}"
        assert proc.stdout.count("ROUND") == 2 and "DONE failures=0" in proc.stdout, name
        assert "in a Python this FMU started" in proc.stdout, name  # the host had none
        got = [float(line.split()[2]) for line in proc.stdout.splitlines() if line.startswith("GET ")]
        expected = fmpy_values(path, folder, outputs, opts[:3] if opts[:1] == ["--set-real"] else [])
        np.testing.assert_allclose(got, list(expected) * 2, rtol=1e-12, atol=0, err_msg=name)


def test_c_host_threads_and_verbatim_messages(c_host, fmu_paths, tmp_path):
    """Calls from a thread that is not the one that loaded Python; a message with printf
    directives arrives verbatim; a bad parameter is fmi2Error (this instance), never fmi2Fatal."""
    path = fmu_paths["SunEphemeris"]
    folder = extract(path, tmp_path / "sun")
    guid, model, opts, _ = plan(path)
    proc = run_host(c_host, folder, model, guid, opts, ["--threads"])
    assert proc.returncode == 0 and "DONE failures=0" in proc.stdout, proc.stdout[-2000:]
    md = fmpy.read_model_description(str(path))
    epoch = next(v.valueReference for v in md.modelVariables if v.name == "epoch")
    proc = run_host(c_host, folder, model, guid, ["--set-string", str(epoch), "bad %s%n%x epoch %d"])
    assert proc.returncode == 3, proc.stdout  # failures reported, no crash (a crash is -11 or 139)
    assert "epoch = 'bad %s%n%x epoch %d'" in proc.stdout
    assert "STATUS fmi2ExitInitializationMode(c) 3" in proc.stdout  # fmi2Error
    assert "ROUND 2" in proc.stdout  # the host went on: a fresh instance after the failed one


SIMULATE_ALL = r"""
import json, sys, fmpy
out = {}
try:
    import numba, scipy, pymsis
    raise SystemExit("this environment must not have numba, scipy or pymsis")
except ImportError:
    pass
for path in sys.argv[1:]:
    r = fmpy.simulate_fmu(path, stop_time=0.045, output_interval=0.015)
    out[path] = [float(r[name][-1]) for name in r.dtype.names[1:] if r[name].dtype.kind == "f"]
print(json.dumps(out))
"""


def test_every_fmu_runs_in_fmpy_with_only_numpy(numpy_only_python, fmu_paths):
    """numpy is the only requirement: no numba, scipy or pymsis in that Python; the results equal
    this environment's to 1e-12 (numba's compiled kernels and the plain-Python ones agree)."""
    paths = [str(p) for _, p in sorted(fmu_paths.items())]
    proc = subprocess.run([str(numpy_only_python), "-c", SIMULATE_ALL, *paths], capture_output=True, text=True,
                          timeout=900)
    assert proc.returncode == 0, proc.stderr[-3000:]
    there = json.loads(proc.stdout.strip().splitlines()[-1])
    for path in paths:
        r = fmpy.simulate_fmu(path, stop_time=0.045, output_interval=0.015)
        here = [float(r[name][-1]) for name in r.dtype.names[1:] if r[name].dtype.kind == "f"]
        np.testing.assert_allclose(there[path], here, rtol=1e-12, atol=1e-300, err_msg=path)


THREE_SYSTEMS = r"""
import sys
import system_ssp
deorbit, detumble, mission = sys.argv[1:4]
r1 = system_ssp.simulate(deorbit, stop_time=7200.0, parameters={"orbit.density_model": "exponential"})
r2 = system_ssp.simulate(deorbit, stop_time=7200.0, parameters={"orbit.density_model": "jacchia_roberts"})
r3 = system_ssp.simulate(detumble)
r4 = system_ssp.simulate(mission, stop_time=2 * 86400.0)
assert r1.final["orbit.density"] != r2.final["orbit.density"]
print("ok", r1.steps, r2.steps, r3.stop_reason, r4.steps)
"""


def test_systems_one_after_another_in_one_process_exit_cleanly(ssp_paths):
    """Two de-orbit runs with different density models (each System extracts its FMUs afresh and
    deletes them when done), the detumble system and two mission days, then a normal interpreter
    exit: status 0, no os._exit anywhere."""
    proc = subprocess.run([sys.executable, "-c", THREE_SYSTEMS, str(ssp_paths["deorbit"]),
                           str(ssp_paths["detumble"]), str(ssp_paths["neighbor_mission_lifetime"])],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert proc.stdout.startswith("ok") and "stop condition detumble.done" in proc.stdout


def test_runtime_config_records_the_build_python(fmu_paths):
    with zipfile.ZipFile(fmu_paths["Gyro"]) as z:
        text = z.read("resources/neighbor_runtime.txt").decode()
    assert f"python_version={sys.version_info[0]}.{sys.version_info[1]}" in text
    if sysconfig.get_config_var("Py_ENABLE_SHARED"):
        assert "libpython=" in text and "python_home=" in text


def _fmi2_cosimulation_functions():
    """The functions a co-simulation FMU must export: the common and co-simulation sections of
    the FMI 2.0 header (FMPy ships the standard's headers), without the model-exchange ones."""
    header = (Path(fmpy.__file__).parent / "c-code" / "fmi2Functions.h").read_text()
    common, rest = header.rsplit("Functions for FMI2 for Model Exchange", 1)  # the declarations come last
    cosimulation = rest.split("Functions for FMI2 for Co-Simulation", 1)[1]
    return {m for part in (common, cosimulation) for m in re.findall(r"FMI2_Export\s+\w+TYPE\s+(fmi2\w+);", part)}


def test_win64_binary_exports_fmi2_and_links_no_python(fmu_paths, tmp_path):
    """The win64 binary (compiled with mingw-w64, not yet run on Windows): exactly the FMI 2.0
    co-simulation functions exported, plus neighborStepIO (our master's batched step, issue 27) and
    neighborSkipTo (a suspended component's clock jump, issue 54), and
    imports from Windows' own DLLs only (the Python DLL is loaded at run time, never linked)."""
    objdump = shutil.which("x86_64-w64-mingw32-objdump")
    with zipfile.ZipFile(fmu_paths["Gyro"]) as z:
        dlls = [n for n in z.namelist() if n.startswith("binaries/win64/")]
        if not dlls or objdump is None:
            pytest.skip("no win64 binary or no mingw-w64 objdump (apt install gcc-mingw-w64-x86-64, as .ci/run does)")
        dll = tmp_path / "Gyro.dll"
        dll.write_bytes(z.read(dlls[0]))
    text = subprocess.run([objdump, "-p", str(dll)], capture_output=True, text=True, check=True).stdout
    exports = set(re.findall(r"^\s*\[\s*\d+\]\s+(\w+)\s*$", text.split("[Ordinal/Name Pointer] Table", 1)[1],
                             re.M))
    required = _fmi2_cosimulation_functions()
    assert len(required) == 34
    ours = {"neighborStepIO", "neighborSkipTo"}  # the master's batched step, its schedule's clock jump
    assert exports == required | ours, (sorted(required - exports), sorted(exports - required))
    imports = {name.lower() for name in re.findall(r"DLL Name: (\S+)", text)}
    assert imports <= {"kernel32.dll", "msvcrt.dll"}, imports
