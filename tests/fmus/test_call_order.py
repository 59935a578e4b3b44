"""A careless host (issue 54): every FMU enforces the FMI 2.0 and 3.0 state machines. A call out
of the standard's order, a non-positive, non-finite or non-contiguous step, a get of an unknown
value reference or through a NULL array, an instantiation with a wrong GUID or resource
location: fmiError (or NULL) with a message naming the call and the state, never a crash.

- FMI 2.0: a C host with no Python (tests/fmus/c_host/fuzz_host.c) makes random call sequences
  from a seed on every FMU and checks each status against the standard's table; the same host
  instantiates and frees one FMU 10,000 times and its memory and file handles stay flat.
- FMI 3.0: the out-of-order calls through FMPy on every FMU.
The legal sequences of every shipped system run unchanged (the rest of the suite)."""
from concurrent.futures import ThreadPoolExecutor
import math
import os
import subprocess
import zipfile

import fmpy
from fmpy.fmi1 import FMICallException
from fmpy.fmi3 import FMU3Slave
import pytest

CLEAN_ENV = {"PATH": "/usr/bin:/bin", "HOME": os.environ.get("HOME", "/tmp")}
CALLS = 200  # per FMU and seed
AT_ONCE = 4


def _fuzz_plan(path):
    """(model identifier, guid, [fuzz options]): a Real input with its start value, a Real output."""
    md = fmpy.read_model_description(str(path))
    opts = []
    inputs = [v for v in md.modelVariables if v.causality == "input" and v.type == "Real" and v.start is not None]
    outputs = [v for v in md.modelVariables if v.causality == "output" and v.type == "Real"]
    if inputs:
        opts += ["--input", str(inputs[0].valueReference), repr(float(inputs[0].start))]
    if outputs:
        opts += ["--output", str(outputs[0].valueReference)]
    return md.coSimulation.modelIdentifier, md.guid, opts


@pytest.fixture(scope="module")
def extracted2(fmu_paths, tmp_path_factory):
    root = tmp_path_factory.mktemp("fuzz")
    out = {}
    for name, path in sorted(fmu_paths.items()):
        with zipfile.ZipFile(path) as z:
            z.extractall(root / name)
        out[name] = (root / name, *_fuzz_plan(path))
    return out


def test_random_call_sequences_get_the_standards_answer_from_every_fmu(fuzz_host, extracted2):
    def run(item):
        k, (name, (folder, model, guid, opts)) = item
        return name, subprocess.run([str(fuzz_host), str(folder), model, guid, "--seed", str(k + 1), "--calls",
                                     str(CALLS), *opts], capture_output=True, text=True, timeout=600, env=CLEAN_ENV)

    with ThreadPoolExecutor(AT_ONCE) as pool:
        results = list(pool.map(run, enumerate(extracted2.items())))
    problems = [f"{name}: exit {proc.returncode}\n{proc.stdout[-2000:]}{proc.stderr[-1000:]}"
                for name, proc in results if proc.returncode != 0 or "mismatches=0" not in proc.stdout]
    assert not problems, "\n".join(problems)
    refused = sum(int(proc.stdout.split("refused=")[1].split()[0]) for _, proc in results)
    assert refused > len(results) * CALLS // 4  # the sequences did try the FMUs (about half out of order)


def test_ten_thousand_instantiations_keep_memory_and_file_handles_flat(fuzz_host, extracted2):
    folder, model, guid, _ = extracted2["SunEphemeris"]
    proc = subprocess.run([str(fuzz_host), str(folder), model, guid, "--cycles", "10000"], capture_output=True,
                          text=True, timeout=600, env=CLEAN_ENV)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    words = proc.stdout.split()
    rss_start, rss_end = int(words[3]), int(words[4])
    fds_start, fds_end = int(words[6]), int(words[7])
    assert fds_end == fds_start, proc.stdout
    assert rss_end - rss_start < 4096, proc.stdout  # kB from cycle 1,000 to 10,000: no leak per instance


def _fmi3_out_of_order(path, tmp_path):
    """{case: the FMU's answer} of out-of-order FMI 3.0 calls, each from the state it names."""
    md = fmpy.read_model_description(str(path))
    folder = tmp_path / md.modelName
    with zipfile.ZipFile(path) as z:
        z.extractall(folder)
    fmu = FMU3Slave(guid=md.guid, unzipDirectory=str(folder), modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName="careless")
    outputs = [v.valueReference for v in md.modelVariables if v.causality == "output" and v.type == "Float64"][:1]
    fmu.instantiate()
    answers = {}

    def initialized():
        fmu.enterInitializationMode(startTime=0.0)
        fmu.exitInitializationMode()

    def case(name, prepare, call):
        fmu.reset()
        prepare()
        try:
            call()
            answers[name] = "accepted"
        except FMICallException as exc:
            answers[name] = f"status {exc.status}"

    case("fmi3DoStep before initialization", lambda: None, lambda: fmu.doStep(0.0, 0.1))
    case("fmi3ExitInitializationMode before entering", lambda: None, fmu.exitInitializationMode)
    case("fmi3EnterInitializationMode twice", lambda: fmu.enterInitializationMode(startTime=0.0),
         lambda: fmu.enterInitializationMode(startTime=0.0))
    case("fmi3DoStep after fmi3Terminate", lambda: (initialized(), fmu.terminate()), lambda: fmu.doStep(0.0, 0.1))
    case("fmi3Terminate twice", lambda: (initialized(), fmu.terminate()), fmu.terminate)
    case("fmi3DoStep with a negative step", initialized, lambda: fmu.doStep(0.0, -0.1))
    case("fmi3DoStep not where the last step ended", lambda: (initialized(), fmu.doStep(0.0, 0.1)),
         lambda: fmu.doStep(0.5, 0.1))
    case("fmi3GetFloat64 of an unknown value reference", initialized, lambda: fmu.getFloat64([99999999]))
    if outputs:
        case("fmi3GetFloat64 before initialization", lambda: None, lambda: fmu.getFloat64(outputs))
    arrays = [v for v in md.modelVariables if v.causality == "output" and v.type == "Float64" and v.dimensions]
    if arrays:  # fewer values than the array's elements: a too-short array for the host's buffer
        size = math.prod(int(d.start) for d in arrays[0].dimensions)
        case("fmi3GetFloat64 with nValues below the array's size", initialized,
             lambda: fmu.getFloat64([arrays[0].valueReference], size - 1))
    for label, token, where in (("a wrong instantiation token", "{not-this-fmu}", folder),
                                ("a wrong resource path", md.guid, folder / "missing")):
        wrong = FMU3Slave(guid=token, unzipDirectory=str(folder), modelIdentifier=md.coSimulation.modelIdentifier,
                          instanceName="wrong")
        wrong.unzipDirectory = str(where)  # the library loaded; the resource path it is given is wrong
        try:
            wrong.instantiate()
            answers[f"fmi3InstantiateCoSimulation with {label}"] = "accepted"
            wrong.freeInstance()
        except Exception:
            answers[f"fmi3InstantiateCoSimulation with {label}"] = "status 3"
    fmu.reset()  # and the legal sequence after all that
    initialized()
    for k in range(3):
        fmu.doStep(k * 0.015, 0.015)
    fmu.terminate()
    fmu.freeInstance()
    return answers


def test_out_of_order_fmi3_calls_are_refused_by_every_fmu(fmu3_paths, tmp_path):
    accepted = {}
    for name, path in sorted(fmu3_paths.items()):
        answers = _fmi3_out_of_order(path, tmp_path)
        assert len(answers) >= 8, name
        bad = {case: answer for case, answer in answers.items() if answer != "status 3"}
        if bad:
            accepted[name] = bad
    assert not accepted, accepted
