"""Native steps (components.core.native, NeighborSlave.arm_native): once numba is in the process,
RigidBody, RcsThrusters, DetumbleController, TrackingController and Gyro hand the binary a compiled
step that it calls instead of their Python do_step, and the thruster pairs, the two laws and the
gyro, with outputs that depend on inputs, a compiled publish it calls instead of their Python publish (a get after a
set, as Gauss-Seidel does). The tracking law runs as the mission runs it: its target and boundary layer
from the inputs.

Through the binary (FMPy loading the built FMUs, FMI 2.0 and 3.0, numba loaded as in a long
run), against the same FMUs with NEIGHBOR_COSIM_NATIVE=0 in a second process: the same outputs
(and FMI 3.0's time) bit for bit over steps with changing inputs, after an FMU state is restored
(the model rebuilt: the step disarmed, then armed again on the new arrays) and after a reset; and
the Python do_step is entered only to arm the step (once, and once more after the state is
restored and after the reset), where without it every step enters it; likewise the Python publish.
"""
import json
import os
import subprocess
import sys

import pytest

pytest.importorskip("numba")

MODELS = ("RigidBody", "RcsThrusters", "DetumbleController", "TrackingController", "Gyro")
# parameters set before the run, and inputs kept >= 0 (the estimator's sigmas)
SETUP = {"TrackingController": {"booleans": {"target_from_input": True}, "nonnegative": ["sigma_attitude_B"],
                                "reals": {"knowledge_sigmas": 3.0, "impulse_bits": 1.0, "rate_sigma": 1e-4}},
         "Gyro": {"reals": {"sigma_sample_time": 0.1}}}
STEPS = 300

RUN = r"""
import json, sys
import numba  # as in a long run: numba is in the process before the FMUs step
import numpy as np
import fmpy
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave

path, steps, unzip, following = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4] == "1"
setup = json.loads(sys.argv[5])
md = fmpy.read_model_description(path)
fmi3 = md.fmiVersion.startswith("3")
wrapper = "neighbor_" + "".join("_" + c.lower() if c.isupper() else c for c in md.modelName).lstrip("_") + ".py"
entered = {"do_step": 0, "publish": 0}

def count(frame, event, arg):  # the wrapper's Python do_step and publish, entered from the binary
    if event == "call" and frame.f_code.co_name in entered and frame.f_code.co_filename.endswith(wrapper):
        entered[frame.f_code.co_name] += 1

REAL, INTEGER = ("Float64", "Int32") if fmi3 else ("Real", "Integer")

def size(v):  # elements of an FMI 3.0 array, 1 for a scalar
    n = 1
    for d in v.dimensions or []:
        n *= int(d.start)
    return n

variables = [v for v in md.modelVariables if v.causality in ("input", "output")]
inputs_of = [v for v in variables if v.causality == "input" and v.type == REAL]
ins = [v.valueReference for v in inputs_of]
n_in = sum(size(v) for v in inputs_of)
outs = {t: [v for v in variables if v.causality == "output" and v.type == t] for t in (REAL, INTEGER, "Boolean")}
time = [v.valueReference for v in md.modelVariables if v.causality == "independent"]  # FMI 3.0
f = (FMU3Slave if fmi3 else FMU2Slave)(guid=md.guid, unzipDirectory=fmpy.extract(path, unzipdir=unzip),
                                       modelIdentifier=md.coSimulation.modelIdentifier, instanceName="native")

def get(kind):
    vrs = [v.valueReference for v in outs[kind]]
    if not fmi3:
        return getattr(f, "get" + kind)(vrs)
    return getattr(f, "get" + kind)(vrs, sum(size(v) for v in outs[kind]))

by_name = {v.name: v.valueReference for v in md.modelVariables}

def start():
    if fmi3:
        f.enterInitializationMode(startTime=0.0)
    else:
        f.setupExperiment(startTime=0.0)
        f.enterInitializationMode()
    if following:  # RigidBody's inertia follows the propellant drawn
        f.setBoolean([by_name["propellant_mass_properties"]], [True])
    for name, value in setup.get("booleans", {}).items():
        f.setBoolean([by_name[name]], [value])
    for name, value in setup.get("reals", {}).items():
        getattr(f, "set" + REAL)([by_name[name]], [value])
    f.exitInitializationMode()

def outputs():  # FMI 3.0: with the time, which the binary keeps after a native step (a get of its own:
    # the time is not one of the model's shared values, so a get with it goes through Python)
    clock = f.getFloat64(time) if fmi3 else []
    return get(REAL) + get(INTEGER) + [bool(b) for b in get("Boolean")] + clock

def step(k, inputs):
    getattr(f, "set" + REAL)(ins, inputs[k])
    before = outputs()  # after the set: the outputs that depend on inputs published again
    f.doStep(k * 0.015, 0.015)
    return before + outputs()

rng = np.random.default_rng(5)
inputs = [rng.uniform(-s, s, n_in).tolist() for s in [0.2] * (steps // 3) + [1e-4] * (steps - steps // 3)]
at = {v.valueReference: sum(size(u) for u in inputs_of[:i]) for i, v in enumerate(inputs_of)}
for v in inputs_of:
    if v.name.split("[")[0] in setup.get("nonnegative", []):
        for row in inputs:
            for i in range(at[v.valueReference], at[v.valueReference] + size(v)):
                row[i] = abs(row[i])
if following:  # the tank drains by 3e-5 kg a step: the inertia follows every few steps (1e-4 kg)
    for k, row in enumerate(inputs):
        row[at[by_name["propellant_used"]]] = 2e-5 * k
        row[at[by_name["rcs_propellant"]]] = 1e-5 * k
f.instantiate()
start()
sys.setprofile(count)
rows, half = [], None
for k in range(steps):
    if k == steps // 2:
        half = getattr(f, "getFMUState" if fmi3 else "getFMUstate")()
    rows.append(step(k, inputs))
getattr(f, "setFMUState" if fmi3 else "setFMUstate")(half)
replay = [step(k, inputs) for k in range(steps // 2, steps)]
f.reset()
start()
again = [step(k, inputs) for k in range(10)]
sys.setprofile(None)
f.terminate()
f.freeInstance()
print(json.dumps({"rows": rows, "replay": replay, "again": again, "entered": entered}))
"""


def _run(path, tmp_path, native, following=False, setup=None):
    env = dict(os.environ, NEIGHBOR_COSIM_NATIVE=native, NEIGHBOR_COSIM_NUMBA="1")
    proc = subprocess.run([sys.executable, "-c", RUN, str(path), str(STEPS), str(tmp_path / f"unzip{native}"),
                           "1" if following else "0", json.dumps(setup or {})],
                          capture_output=True, text=True, env=env, timeout=600)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout.strip().splitlines()[-1])


@pytest.mark.parametrize("fmi", ("2.0", "3.0"))
@pytest.mark.parametrize("model", MODELS)
def test_native_step_gives_the_python_steps_bits(fmu_paths, fmu3_paths, tmp_path, model, fmi):
    path = (fmu_paths if fmi == "2.0" else fmu3_paths)[model]
    setup = SETUP.get(model)
    native, python = _run(path, tmp_path, "1", setup=setup), _run(path, tmp_path, "0", setup=setup)
    assert native["rows"] == python["rows"]  # bit for bit (JSON gives floats back exactly)
    # (FMI 3.0: with the time, which the restored state and the reset set back)
    assert native["replay"] == native["rows"][STEPS // 2:] == python["replay"]
    assert native["again"] == native["rows"][:10] == python["again"]
    assert python["entered"]["do_step"] == STEPS + STEPS // 2 + 10
    # native: the first step arms it, the step after the restored state and after the reset re-arm it
    assert native["entered"]["do_step"] == 3
    if model != "RigidBody":  # its outputs depend on no input: a set leaves them fresh
        assert python["entered"]["publish"] >= STEPS + STEPS // 2 + 10
        # before each of the three Python steps (the step not armed yet) the publish is Python too,
        # and inside them for a step that ends with publish_after_step
        assert native["entered"]["publish"] == (6 if model == "Gyro" else 3)
    assert len({tuple(r) for r in native["rows"]}) > 5  # the outputs moved (the laws quantize them)


def test_native_step_follows_the_propellant_as_the_python_step(fmu_paths, tmp_path):
    """RigidBody with propellant_mass_properties: native while the propellant drawn stays within
    mass_properties.RESOLUTION of the amount the inertia follows; the steps where it moved past it
    go through Python (which recomputes the inertia), the rest not; the same bits throughout."""
    native = _run(fmu_paths["RigidBody"], tmp_path, "1", following=True)
    python = _run(fmu_paths["RigidBody"], tmp_path, "0", following=True)
    assert native["rows"] == python["rows"]
    assert native["replay"] == native["rows"][STEPS // 2:] == python["replay"]
    assert native["again"] == native["rows"][:10] == python["again"]
    steps = STEPS + STEPS // 2 + 10
    assert python["entered"]["do_step"] == steps
    # 3e-5 kg a step: the inertia follows at about every fourth step, which the Python step takes
    assert steps // 5 < native["entered"]["do_step"] < steps // 2
    centre = [row[-3:] for row in native["rows"]]  # center_of_mass_B, the last Real output after the step
    assert len({tuple(c) for c in centre}) > STEPS // 5  # the centre of mass moved as the tank drained
