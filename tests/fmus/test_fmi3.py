"""Every FMU of ours as an FMI 3.0 co-simulation FMU (build/fmus3): written from the same
declarations as its FMI 2.0 twin (arrays with dimensions, units, descriptions, output
dependencies), valid for `fmpy validate`, and run by fmusim (the Reference-FMUs' C simulator, no
Python in its process) with the results of its FMI 2.0 twin in the same host; the FMI 3.0 calls
keep the runtime's guarantees (errors as a status with a message, never a crash)."""
from ctypes import POINTER, byref, c_bool, c_double, c_int, c_size_t, c_uint32, c_void_p
import os
import xml.etree.ElementTree as ET
import zipfile

import fmpy
from fmpy.fmi3 import FMU3Slave
from fmpy.validation import validate_fmu
import numpy as np
import pytest

import fmusim_host
from system_ssp import builder

# every FMU, named from its wrapper (neighbor_<snake_case>.py, a test holds the names to it): on a
# fresh clone nothing is built when the tests are collected
FMU_NAMES = sorted("".join(w.capitalize() for w in p.stem[len("neighbor_"):].split("_"))
                   for p in builder.wrapper_scripts())


def _root(path):
    with zipfile.ZipFile(path) as z:
        return ET.fromstring(z.read("modelDescription.xml"))


def test_every_fmi3_fmu_is_valid_and_declares_its_arrays(fmu_paths, fmu3_paths):
    """fmpy's validation passes for each; vectors and matrices are arrays with dimensions (the
    rigid body's q_BN Float64[4], inertia_B Float64[3,3]), with units, descriptions and the
    FMI 2.0 twin's variables element for element."""
    for name, path in fmu3_paths.items():
        assert validate_fmu(str(path)) == [], name
        md2, md3 = fmpy.read_model_description(str(fmu_paths[name])), fmpy.read_model_description(str(path))
        assert md3.fmiVersion == "3.0"
        assert md3.coSimulation.canGetAndSetFMUstate == md2.coSimulation.canGetAndSetFMUstate
        elements = sum(int(np.prod([int(d.start) for d in v.dimensions])) if v.dimensions else 1
                       for v in md3.modelVariables if v.causality != "independent")
        assert elements == len(md2.modelVariables), name
        for v in md3.modelVariables:
            assert v.description, f"{name}.{v.name}"
    root = _root(fmu3_paths["RigidBody"])
    q = root.find("ModelVariables/Float64[@name='q_BN']")
    assert [d.get("start") for d in q.findall("Dimension")] == ["4"] and q.get("unit") == "1"
    assert q.get("description") == "Attitude quaternion of B relative to N, scalar last"
    inertia = root.find("ModelVariables/Float64[@name='inertia_B']")
    assert [d.get("start") for d in inertia.findall("Dimension")] == ["3", "3"] and inertia.get("unit") == "kg.m2"
    assert root.find("CoSimulation").get("hasEventMode") == "false"


def test_output_dependencies_carry_over(fmu_paths, fmu3_paths):
    """Each FMI 3.0 output depends on the variables holding the inputs its FMI 2.0 elements depend
    on (a feedthrough stays declared: the master orders components by it)."""
    for name in fmu3_paths:
        md2 = fmpy.read_model_description(str(fmu_paths[name]))
        md3 = fmpy.read_model_description(str(fmu3_paths[name]))
        base = {v.name: v.name.split("[")[0] for v in md2.modelVariables}
        expected = {}
        for u in md2.outputs:
            expected.setdefault(base[u.variable.name], set()).update(base[d.name] for d in u.dependencies or [])
        got = {u.variable.name: {d.name for d in u.dependencies or []} for u in md3.outputs}
        assert got == expected, name


@pytest.mark.parametrize("name", FMU_NAMES)
def test_fmi3_fmu_in_fmusim_without_python_equals_its_fmi2_twin(name, fmu_paths, fmu3_paths, fmusim, tmp_path):
    """fmusim runs the FMI 3.0 FMU in its own process with nothing of Python in the environment
    (the runtime starts the machine's CPython) and records the same outputs, value for value, as
    the FMI 2.0 twin in the same host."""
    results = {}
    for version, path in (("2", fmu_paths[name]), ("3", fmu3_paths[name])):
        out = tmp_path / f"{name}{version}.csv"
        proc = fmusim_host.run(fmusim, path, out, 0.045, 0.015)
        assert proc.returncode == 0, f"FMI {version}: {proc.stdout[-2000:]}{proc.stderr[-2000:]}"
        results[version] = fmusim_host.read(out)
    assert results["3"].keys() == results["2"].keys()
    assert len(results["3"]["time"]) == 4
    for variable, values in results["2"].items():
        assert results["3"][variable].tolist() == values.tolist(), variable


def _slave(path, tmp_path, name="inst"):
    md = fmpy.read_model_description(str(path))
    folder = fmpy.extract(str(path), str(tmp_path / name))
    messages = []
    slave = FMU3Slave(guid=md.guid, unzipDirectory=folder, modelIdentifier=md.coSimulation.modelIdentifier,
                      instanceName=name)
    slave.instantiate(logMessage=lambda env, status, category, message: messages.append((status, message.decode())))
    return md, slave, messages


def _vr(md, name):
    return next(v.valueReference for v in md.modelVariables if v.name == name)


def test_fmi3_calls_keep_the_runtimes_guarantees(fmu3_paths, tmp_path):
    """Through FMPy's FMI 3.0 binding, in this process: an array is read whole; time answers the
    time reached; a wrong number of values, a value reference inside an array, a type the FMU
    does not have and setting time are each fmi3Error with a message, and the instance goes on;
    FMU state: get, step on, set back, step again gives the same values."""
    md, fmu, messages = _slave(fmu3_paths["RigidBody"], tmp_path)
    q, omega, time = _vr(md, "q_BN"), _vr(md, "omega_BN_B"), _vr(md, "time")
    fmu.enterInitializationMode(startTime=0.0)
    fmu.setFloat64([_vr(md, "omega0")], [0.1, -0.2, 0.05])
    fmu.exitInitializationMode()
    fmu.doStep(0.0, 0.1)
    assert fmu.getFloat64([time]) == [pytest.approx(0.1, abs=0)]
    assert len(fmu.getFloat64([q, omega], nValues=7)) == 7
    state = fmu.getFMUState()
    fmu.doStep(0.1, 0.1)
    after = fmu.getFloat64([q], nValues=4)
    fmu.setFMUState(state)
    fmu.doStep(0.1, 0.1)
    assert fmu.getFloat64([q], nValues=4) == after
    fmu.freeFMUState(state)
    c = fmu.component
    values = (c_double * 3)()
    vr = (c_uint32 * 1)(q)
    for call, args, text in [
        ("fmi3GetFloat64", (c, vr, 1, values, 3), "the variables asked for have 4 values, the host gave room for 3"),
        ("fmi3GetFloat64", (c, (c_uint32 * 1)(q + 1), 1, values, 1), f"value reference {q + 1} is not a variable"),
        ("fmi3GetFloat32", (c, vr, 1, values, 1), "this FMU has no variable of that type"),
        ("fmi3SetFloat64", (c, (c_uint32 * 1)(time), 1, values, 1), "time (the independent variable) cannot be set"),
    ]:
        messages.clear()
        fn = getattr(fmu.dll, call)
        fn.argtypes, fn.restype = [c_void_p, POINTER(c_uint32), c_size_t, c_void_p, c_size_t], c_int
        assert fn(*args) == 3, call
        assert any(text in m for _, m in messages), (call, messages)
    fmu.doStep(0.2, 0.1)  # the instance goes on
    assert fmu.getFloat64([time]) == [pytest.approx(0.3)]
    fmu.terminate()
    fmu.freeInstance()


def test_fmi3_instantiation_refusals(fmu3_paths, tmp_path):
    """A token from another build, or model exchange: no instance, the reason in the log."""
    md = fmpy.read_model_description(str(fmu3_paths["Gyro"]))
    folder = fmpy.extract(str(fmu3_paths["Gyro"]), str(tmp_path / "g"))
    for guid, interface, text in [("{not-this-build}", "cs", "is not this FMU's GUID"),
                                  (md.guid, "me", "this FMU supports co-simulation only")]:
        messages = []
        fmu = FMU3Slave(guid=guid, unzipDirectory=folder, modelIdentifier=md.coSimulation.modelIdentifier,
                        instanceName="x")
        log = lambda env, status, category, message, messages=messages: messages.append(message.decode())  # noqa: E731
        with pytest.raises(Exception, match="Failed to instantiate"):
            if interface == "cs":
                fmu.instantiate(logMessage=log)
            else:
                from fmpy.fmi3 import FMU3Model
                FMU3Model(guid=guid, unzipDirectory=folder, modelIdentifier=md.coSimulation.modelIdentifier,
                          instanceName="x").instantiate(logMessage=log)
        assert any(text in m for m in messages), messages


def test_do_step_reports_no_event_and_the_time_reached(fmu3_paths, tmp_path):
    md, fmu, _ = _slave(fmu3_paths["Gyro"], tmp_path)
    fmu.enterInitializationMode(startTime=5.0)
    fmu.exitInitializationMode()
    event, terminate, early, reached = c_bool(True), c_bool(True), c_bool(True), c_double(0.0)
    step = fmu.dll.fmi3DoStep
    step.argtypes = [c_void_p, c_double, c_double, c_bool] + [POINTER(c_bool)] * 3 + [POINTER(c_double)]
    assert step(fmu.component, 5.0, 0.5, True, byref(event), byref(terminate), byref(early), byref(reached)) == 0
    assert (event.value, terminate.value, early.value, reached.value) == (False, False, False, 5.5)
    fmu.terminate()
    fmu.freeInstance()


def test_docs_name_the_fmi3_features_each_fmu_uses(fmu3_paths):
    """docs/interoperability.md's table of arrays, types and state per FMU is what the build
    declares (written by features_table: regenerate it when an FMU's interface changes)."""
    from paths import REPO
    from system_ssp.fmi3_description import FEATURES_BEGIN, FEATURES_END, features_table

    path = REPO / "docs" / "interoperability.md"
    table = features_table(list(fmu3_paths.values()))
    docs = path.read_text()
    if os.environ.get("NEIGHBOR_WRITE_DOCS") == "1":
        before, rest = docs.split(FEATURES_BEGIN, 1)
        path.write_text(before + FEATURES_BEGIN + "\n" + table + "\n" + FEATURES_END
                        + rest.split(FEATURES_END, 1)[1])
        docs = path.read_text()
    assert docs.split(FEATURES_BEGIN, 1)[1].split(FEATURES_END, 1)[0].strip() == table, \
        "docs/interoperability.md's FMI 3.0 features table is not the build's (NEIGHBOR_WRITE_DOCS=1 writes it)"
