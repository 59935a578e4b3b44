"""The master's batched step (issue 27): our runtime's neighborStepIO sets a component's inputs,
steps it and reads its outputs in one call into the FMU. It must give the standard calls' results
bit for bit, be used only where the library offers it, and report a failure as the call that
failed."""
import ctypes

import fmpy
from fmpy.fmi2 import FMU2Slave
import pytest

from paths import DATA, REPO
import system_ssp
from system_ssp.master import instances
from system_ssp.master.system import simulate
from system_ssp.ssp.writer import single_fmu_system


BATCHED_STEPPER = instances.InstanceTable._batched_stepper


def _run(path, batched, monkeypatch, **options):
    """simulate(path) with or without the batched step; also the components it stepped batched."""
    monkeypatch.setattr(instances, "BATCHED_STEPS", batched)
    used = []
    original = BATCHED_STEPPER

    def counting(table, ci, step_io):
        used.append(table.system.comps[ci].name)
        return original(table, ci, step_io)

    monkeypatch.setattr(instances.InstanceTable, "_batched_stepper", counting)
    return simulate(path, **options), used


# detumble: Real connections only; attitude_determination: Real and Boolean (the sensors' valid
# flags), with feedthrough sensors refreshed through the standard calls between batched steps
@pytest.mark.parametrize("system", ["detumble", "attitude_determination", "sun_avoidance_slew"])
def test_batched_steps_equal_the_standard_calls(ssp_paths, monkeypatch, system):
    standard, used_standard = _run(ssp_paths[system], False, monkeypatch)
    batched, used = _run(ssp_paths[system], True, monkeypatch)
    # every component is our runtime's, connected by Real, Integer and Boolean connections only
    with system_ssp.System(ssp_paths[system]) as loaded:
        assert used_standard == [] and used == [c.name for c in loaded.comps]
    assert list(batched.names) == list(standard.names)
    assert batched.to_pandas().equals(standard.to_pandas())  # every recorded value, bit for bit
    assert batched.final == standard.final and batched.stop_reason == standard.stop_reason


def _instance(fmu_path, tmp_path):
    md = fmpy.read_model_description(str(fmu_path))
    unzipdir = fmpy.extract(str(fmu_path), str(tmp_path / "unzip"))
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName="io")
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    return md, fmu


def test_the_runtime_step_reports_the_call_that_failed(built, tmp_path):
    """neighborStepIO's `failed`: 1 + type for a set, 5 + type for a get, with the status and
    the message the standard call gives (an unknown value reference here)."""
    md, fmu = _instance(REPO / "build" / "fmus" / "TorqueSelector.fmu", tmp_path)
    try:
        step_io = fmu.dll.neighborStepIO
        step_io.argtypes = [ctypes.c_void_p, ctypes.POINTER(instances.StepIO)]
        step_io.restype = ctypes.c_int
        reals = [v for v in md.modelVariables if v.type == "Real"]
        inp = next(v for v in reals if v.causality == "input")
        out = next(v for v in reals if v.causality == "output")
        good_in, good_out = (ctypes.c_uint * 1)(inp.valueReference), (ctypes.c_uint * 1)(out.valueReference)
        bad = (ctypes.c_uint * 1)(99999)
        value, result = (ctypes.c_double * 1)(0.0), (ctypes.c_double * 1)(float("nan"))

        def call(in_vr, out_vr):
            io = instances.StepIO()
            io.t, io.h = 0.0, 0.1
            io.n_in[0], io.in_vr[0], io.in_val[0] = 1, ctypes.addressof(in_vr), ctypes.addressof(value)
            io.n_out[0], io.out_vr[0], io.out_val[0] = 1, ctypes.addressof(out_vr), ctypes.addressof(result)
            io.send[0] = 1
            return step_io(fmu.component, ctypes.byref(io)), io.failed

        assert call(good_in, good_out) == (0, 0) and result[0] == result[0]  # a value was read
        assert call(bad, good_out) == (3, 1)  # fmi2Error in the Real set
        fmu.reset()  # the error made the instance refuse further calls until reset
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        assert call(good_in, bad) == (3, 5)  # fmi2Error in the Real get
    finally:
        fmu.freeInstance()


def test_other_fmus_are_stepped_with_the_standard_calls(monkeypatch, tmp_path):
    """A third-party FMU (a Modelica Reference FMU) has no neighborStepIO: the master steps it with
    fmi2SetReal/fmi2DoStep/fmi2GetReal, the batched path is never chosen."""
    path = single_fmu_system(DATA / "reference_fmus" / "2.0" / "Dahlquist.fmu", tmp_path)
    result, used = _run(path, True, monkeypatch, stop_time=1.0, step_size=0.1)
    assert used == [] and result.steps > 0
