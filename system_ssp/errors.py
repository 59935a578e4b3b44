"""Exceptions raised by the master."""


class SSPError(Exception):
    """A problem with the system description, its parameters or the caller's arguments.

    The message names the file (and line), component, variable or connection concerned.
    """


class SimulationError(SSPError):
    """An FMU failed while the system was being instantiated, initialized or stepped.

    The message names the component, the FMI call, the simulation time and includes the
    messages the FMU logged (for pythonfmu FMUs, the Python exception text).
    """
