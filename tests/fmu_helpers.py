"""Test helpers for our FMUs: the checks every FMU must pass, and an instance driven
directly through FMPy."""
import fmpy
from fmpy.fmi2 import FMU2Slave
from fmpy.validation import validate_fmu


def instantiate(path, unzip_parent, name, start_time=0.0, initialize=False):
    """(FMU2Slave after fmi2SetupExperiment, {variable name: value reference}); the FMU is
    extracted to `unzip_parent / name`. With `initialize`, also through initialization mode."""
    md = fmpy.read_model_description(str(path))
    unzip = fmpy.extract(str(path), unzipdir=str(unzip_parent / name))
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzip, modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName=name)
    fmu.instantiate()
    fmu.setupExperiment(startTime=start_time)
    if initialize:
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
    return fmu, {v.name: v.valueReference for v in md.modelVariables}


def check_declarations(path):
    """Assert what every FMU of ours must satisfy and return {output: sorted input names it
    depends on directly}: fmpy validation is clean; every variable has causality, variability
    and a description, every Real a defined unit; the FMU restores its state; Outputs and
    InitialUnknowns list exactly the outputs."""
    assert validate_fmu(str(path)) == [], path.name
    md = fmpy.read_model_description(str(path))
    units = {u.name for u in md.unitDefinitions}
    for v in md.modelVariables:
        assert v.causality and v.variability and v.description, (path.name, v.name)
        if v.type == "Real":
            assert v.unit in units, (path.name, v.name, v.unit)
    assert md.coSimulation.canGetAndSetFMUstate, path.name
    outputs = {v for v in md.modelVariables if v.causality == "output"}
    assert {u.variable for u in md.outputs} == outputs
    assert {u.variable for u in md.initialUnknowns} == outputs
    return {u.variable.name: sorted(d.name for d in u.dependencies) for u in md.outputs}
