"""What every command shares, the generic tools and the NEIGHBOR application alike: the console
options (system_ssp.tools.arguments, imported from here too), a results folder written as one
unit, --set parsing, and where the built systems are."""
from contextlib import contextmanager

from ..atomic import StagedFolder
from ..builder import resolve_system
from ..locations import SSP_DIR
from ..errors import RunInterrupted, RunTimedOut, SimulationError, SSPError
from ..master import write_result
from .arguments import (LOG_LEVELS, ArgumentParser, add_console_arguments, console_settings, finite_float,
                        positive_float, positive_int, release_console, run_index, whole_number)

# Where the builder packs the systems (build/ssp in a checkout; see system_ssp.locations).
DEFAULT_SSP_DIR = SSP_DIR
__all__ = ["LOG_LEVELS", "ArgumentParser", "DEFAULT_SSP_DIR", "add_console_arguments", "console_settings",
           "finite_float", "parse_sets", "positive_float", "positive_int", "release_console", "run_index",
           "staged_results", "system_path", "whole_number"]


def system_path(name: str) -> str:
    """A system named on the command line: a path as given, or the name of a shipped system (its
    packed file in the build folder, built first when missing); SSPError listing the systems
    when it is neither (system_ssp.builder.resolve_system)."""
    return str(resolve_system(name))


@contextmanager
def staged_results(out, partial_name):
    """An application's results folder as one unit: a StagedFolder for `out` (None without `out`),
    created now so that an unwritable place is refused before any run. The body writes into its
    `.path` and calls `.commit()`. A run that stops (failed, interrupted, timed out) leaves its
    rows in `partial_name(err)` inside <out>.partial; any other failure removes the staging."""
    staged = StagedFolder(out) if out is not None else None
    try:
        yield staged
    except (SimulationError, RunInterrupted, RunTimedOut) as err:
        if staged is not None:
            if err.result is not None:
                write_result(err.result.data, staged.path / partial_name(err), err.result.units)
            err.partial_file = staged.commit_partial(str(err))
        raise
    except BaseException:
        if staged is not None:
            staged.discard()
        raise


def parse_sets(items):
    """--set COMP.VAR=VALUE arguments as {name: value text} (the master converts and checks)."""
    out = {}
    for item in items:
        if "=" not in item:
            raise SSPError(f"--set {item!r}: expected component.variable=value")
        k, v = item.split("=", 1)
        out[k.strip()] = v.strip()
    return out
