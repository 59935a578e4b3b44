"""Exceptions raised by the master, and how their messages name an option."""
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Iterator

# How a message names an option that would change the outcome: as the command line spells it
# (`--algorithm jacobi`) while the command line runs, else as the Python API does
# (`algorithm='jacobi'`), so that the advice is what the reader can type where they are.
_SPELLING: ContextVar[str] = ContextVar("system_ssp_option_spelling", default="api")


def option(command_line: str, api: str) -> str:
    """`command_line` inside `command_line_spelling()`, else `api`."""
    return command_line if _SPELLING.get() == "cli" else api


@contextmanager
def command_line_spelling() -> Iterator[None]:
    """Messages raised inside name options as the command line spells them."""
    token = _SPELLING.set("cli")
    try:
        yield
    finally:
        _SPELLING.reset(token)


class SSPError(Exception):
    """A problem with the system description, its parameters or the caller's arguments.

    The message names the file (and line), component, variable or connection concerned.
    """


class _Stopped(SSPError):
    """A run that ended before its stop time; what it had computed travels with it.

    result:       a Result with the rows recorded so far (`result.partial` is True), or None when
                  the run stopped before its first row (instantiation, initialization).
    partial_file: where those rows were written (System.run with an output file), or None.
    partial_note: why they could not be written there, or None.
    """
    result = None
    partial_file = None
    partial_note = None


class SimulationError(_Stopped):
    """An FMU failed while the system was being instantiated, initialized or stepped.

    The message names the component, the FMI call, the simulation time and includes the
    messages the FMU logged (for pythonfmu FMUs, the Python exception text).
    """


class RunInterrupted(_Stopped):
    """The run was stopped by SIGINT (Ctrl-C), SIGTERM or SIGHUP at a communication point.

    signal: the signal number (exit code 128 + signal in the command line)."""

    def __init__(self, message: str, signal: int) -> None:
        super().__init__(message)
        self.signal = signal


class RunTimedOut(_Stopped):
    """The run passed its wall-clock limit (`System.run(timeout=...)`) and was stopped at a
    communication point."""


class RealTimeOverrun(_Stopped):
    """A run paced to wall time with `stop_on_overrun` fell a whole communication step behind
    (`System.run(real_time=..., stop_on_overrun=True)`) and was stopped there."""
