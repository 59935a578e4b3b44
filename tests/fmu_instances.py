"""A co-simulation instance of one of our FMUs, driven directly through FMPy in tests."""
import fmpy
from fmpy.fmi2 import FMU2Slave


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
