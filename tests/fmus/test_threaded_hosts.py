"""Every FMU in hosts that call from several threads at once (issue 54): libcosim steps FMUs on a
thread pool and any host may instantiate from worker threads. Each FMU is listed twice (the same
file instantiated twice at once); 8 threads instantiate, initialize, set, step, read every Real
output, terminate and free them, in a fresh process each time; the values must equal a
single-threaded run of the same jobs bit for bit.

Each FMU's first scalar Real input (where it has one) is set before every step.
- a C host with pthreads and no Python in it (tests/fmus/c_host/threaded_host.c), FMI 2.0;
- FMPy in a Python process (ctypes releases the GIL around each call), FMI 2.0 and FMI 3.0.
"""
from concurrent.futures import ThreadPoolExecutor
import math
import os
import subprocess
import sys
import zipfile

import fmpy
import pytest

REPEATS = 20  # fresh processes per host
AT_ONCE = 4  # of them running together (each spends most of its time waiting on the GIL)
THREADS = 8
STEPS, STEP = 3, 0.015
CLEAN_ENV = {"PATH": "/usr/bin:/bin", "HOME": os.environ.get("HOME", "/tmp")}


def _real_outputs(path):
    md = fmpy.read_model_description(str(path))
    return md, [v.valueReference for v in md.modelVariables if v.causality == "output" and v.type == "Real"][:64]


def _real_input(md, real="Real"):
    """(value reference, value) of the FMU's first Real input with a start value, set to that value
    before every step (any other value may not be one the model takes: a unit quaternion's
    element, a direction cosine), or None."""
    for v in md.modelVariables:
        if v.causality == "input" and v.type == real and v.start is not None and not v.dimensions:
            return v.valueReference, float(v.start)
    return None


@pytest.fixture(scope="module")
def extracted(fmu_paths, tmp_path_factory):
    """{name: (folder, model identifier, guid, [Real output value references])}, FMI 2.0."""
    root = tmp_path_factory.mktemp("threaded")
    out = {}
    for name, path in sorted(fmu_paths.items()):
        folder = root / name
        with zipfile.ZipFile(path) as z:
            z.extractall(folder)
        md, vrs = _real_outputs(path)
        out[name] = (folder, md.coSimulation.modelIdentifier, md.guid, vrs, _real_input(md))
    return out


def _parallel(commands):
    """Run the commands, AT_ONCE at a time: their completed processes in order."""
    def run(cmd):
        return subprocess.run(cmd, capture_output=True, text=True, timeout=600, env=CLEAN_ENV)

    with ThreadPoolExecutor(AT_ONCE) as pool:
        return list(pool.map(run, commands))


def test_c_host_threads_give_the_single_threaded_values(threaded_host, extracted, tmp_path):
    jobs = tmp_path / "jobs.txt"
    lines = [f"{folder} {model} {guid} {','.join(map(str, vrs)) or '-'}" + (f" {inp[0]} {inp[1]!r}" if inp else "")
             for folder, model, guid, vrs, inp in extracted.values()]
    jobs.write_text("".join(line + "\n" + line + "\n" for line in lines))  # every FMU twice
    base = [str(threaded_host), str(jobs), "--steps", str(STEPS), "--step", str(STEP)]
    reference = _parallel([base + ["--threads", "1"]])[0]
    assert reference.returncode == 0, reference.stdout[-3000:] + reference.stderr[-2000:]
    expected = reference.stdout.splitlines()[:-1]
    assert len([line for line in expected if line.startswith("JOB ")]) == 2 * len(extracted)
    runs = _parallel([base + ["--threads", str(THREADS)]] * REPEATS)
    for k, proc in enumerate(runs):
        assert proc.returncode == 0, f"run {k}: exit {proc.returncode}\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}"
        assert proc.stdout.splitlines()[:-1] == expected, f"run {k} differs from the single-threaded run"


FMPY_HOST = r'''
import sys, json
from concurrent.futures import ThreadPoolExecutor
import fmpy
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave

jobs, threads, steps, h = json.loads(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4])

def run(k):
    folder, model, guid, vrs, version, size, inp = jobs[k]
    if version == 3:
        fmu = FMU3Slave(guid=guid, unzipDirectory=folder, modelIdentifier=model, instanceName=f"job{k}")
        fmu.instantiate()
        fmu.enterInitializationMode(startTime=0.0)
        fmu.exitInitializationMode()
        get = lambda vrs: fmu.getFloat64(vrs, size)
        put = fmu.setFloat64
    else:
        fmu = FMU2Slave(guid=guid, unzipDirectory=folder, modelIdentifier=model, instanceName=f"job{k}")
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        get = fmu.getReal
        put = fmu.setReal
    values = []
    for i in range(steps):
        if inp:
            put([inp[0]], [inp[1]])
        fmu.doStep(i * h, h)
        values.append([float(x).hex() for x in get(vrs)] if vrs else [])
    fmu.terminate()
    fmu.freeInstance()
    return values

with ThreadPoolExecutor(threads) as pool:
    print(json.dumps(list(pool.map(run, range(len(jobs))))))
'''


@pytest.fixture(scope="module")
def fmpy_jobs(extracted, fmu3_paths, tmp_path_factory):
    """Every FMU twice as FMI 2.0 and twice as FMI 3.0 (its output variables as FMI 3.0 declares them)."""
    root = tmp_path_factory.mktemp("threaded3")
    jobs = []
    for name, (folder, model, guid, vrs, inp) in extracted.items():
        jobs += [[str(folder), model, guid, vrs, 2, len(vrs), inp]] * 2
        path = fmu3_paths[name]
        folder3 = root / name
        with zipfile.ZipFile(path) as z:
            z.extractall(folder3)
        md3 = fmpy.read_model_description(str(path))
        outputs3 = [v for v in md3.modelVariables if v.causality == "output" and v.type == "Float64"][:64]
        size = sum(math.prod(int(d.start) for d in v.dimensions) for v in outputs3)  # arrays' elements
        jobs += [[str(folder3), md3.coSimulation.modelIdentifier, md3.instantiationToken,
                  [v.valueReference for v in outputs3], 3, size, _real_input(md3, "Float64")]] * 2
    return jobs


def test_fmpy_threads_give_the_single_threaded_values(fmpy_jobs):
    import json

    def command(threads):
        return [sys.executable, "-c", FMPY_HOST, json.dumps(fmpy_jobs), str(threads), str(STEPS), str(STEP)]

    reference = _parallel([command(1)])[0]
    assert reference.returncode == 0, reference.stderr[-3000:]
    expected = json.loads(reference.stdout)
    assert len(expected) == len(fmpy_jobs)
    assert all(len(values) == STEPS for values in expected)
    for k, proc in enumerate(_parallel([command(THREADS)] * REPEATS)):
        assert proc.returncode == 0, f"run {k}: exit {proc.returncode}\n{proc.stderr[-3000:]}"
        assert json.loads(proc.stdout) == expected, f"run {k} differs from the single-threaded run"
