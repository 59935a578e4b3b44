"""system_ssp: a co-simulation master for flat SSP 1.0 systems of FMI 2.0 co-simulation FMUs.

    result = system_ssp.simulate("detumble", stop_time=20.0)   # a shipped system by name, or a path
    options = system_ssp.RunOptions(parameter_sets=["parameters/slew_case2.ssv"], outputs=["dynamics.q_BN[4]"])
    with system_ssp.System("build/ssp/slew.ssp") as system:   # load once, run many times
        r = system.run(options, observers=[my_observer])        # keywords: a shorthand for RunOptions fields

`SSPError` names the file and line, component, variable or connection of a bad input;
`SimulationError` (a subclass) an FMU that failed, with the messages it logged; `RunInterrupted`
(a subclass) a run stopped by Ctrl-C or SIGTERM. Both carry the rows recorded so far (`err.result`). The algorithms,
the parameter order, the `org.neighbor-cosim.master` annotation and `nc:Schedule` are described
in docs/master.md.
"""
import importlib
import logging
from typing import TYPE_CHECKING, Any

from .errors import RealTimeOverrun, RunInterrupted, SimulationError, SSPError
from .version import __version__

if TYPE_CHECKING:
    from .master import (Observer, Result, RunOptions, RunView, StepInfo, System, simulate, write_csv_atomic,
                         write_result)

_FROM_MASTER = ("Observer", "Result", "RunOptions", "RunView", "StepInfo", "System", "simulate", "write_csv_atomic",
                "write_result")


def __getattr__(name: str) -> Any:
    # the master (numpy, fmpy, lxml) is imported on first use, so that the command line's first
    # code (system_ssp.launch) runs before those imports
    if name in _FROM_MASTER:
        return getattr(importlib.import_module(".master", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


# A library prints nothing by itself: the master's and the FMUs' messages go to the "system_ssp"
# loggers for the application to show (the command line does, see --log-level).
logging.getLogger("system_ssp").addHandler(logging.NullHandler())

__all__ = ["simulate", "System", "RunOptions", "Result", "Observer", "RunView", "StepInfo", "SSPError",
           "SimulationError", "RunInterrupted", "RealTimeOverrun", "write_csv_atomic", "write_result", "__version__"]
