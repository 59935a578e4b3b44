"""system_ssp: a co-simulation master for flat SSP 1.0 systems of FMI 2.0 co-simulation FMUs.

    result = system_ssp.simulate("build/ssp/detumble.ssp", stop_time=20.0)
    with system_ssp.System("build/ssp/slew.ssp") as system:   # load once, run many times
        r = system.run(parameter_sets=["parameters/slew_case2.ssv"], outputs=["dynamics.q_BN[4]"])

`SSPError` names the file and line, component, variable or connection of a bad input;
`SimulationError` (a subclass) an FMU that failed, with the messages it logged. The algorithms,
the parameter order, the `org.neighbor-cosim.master` annotation and `nc:Schedule` are described
in docs/master.md.
"""
from .errors import SimulationError, SSPError
from .master import Result, System, simulate, write_csv_atomic

__version__ = "0.2.0"

__all__ = ["simulate", "System", "Result", "SSPError", "SimulationError", "write_csv_atomic", "__version__"]
