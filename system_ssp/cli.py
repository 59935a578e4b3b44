"""Command line: `neighbor-cosim` (or `python -m system_ssp`) with the subcommands `run`,
`info`, `compose`, `export-fmu`, `replace`, `compare`, `flatten`, `convert`, `campaign`, `thesis`,
`deorbit-study`, `mission`, `propulsion`, `validation`, `build` and `export`, and `--version`.

Exit codes: 0 done; 1 an application's result is incomplete (mission or de-orbit study without
re-entry, a thesis number out of tolerance), or a run paced with --real-time and
--stop-on-overrun fell behind; 2 bad input or a failed FMU (one line naming the
file and line, component or variable); 3 an unexpected error; 130 interrupted by Ctrl-C (SIGINT),
143 by SIGTERM, 129 by SIGHUP. A run that fails or is interrupted writes what it had recorded to
<output>.partial.csv (the mission and the de-orbit study: <out>.partial/) and says where.

This module imports only what parsing needs (no numpy, FMPy, numba or model): a subcommand's
module is imported when it runs (`COMMANDS`), so `--version` and `--help` answer at once and
each subcommand pays only for its own imports.
"""
import errno
import importlib
import os
import signal
import sys
import traceback

from . import __version__
from .errors import RealTimeOverrun, RunInterrupted, SimulationError, SSPError, command_line_spelling
from .tools.arguments import (ArgumentParser, add_console_arguments, finite_float, positive_float, positive_int,
                              release_console)

# each subcommand: "module:function(argv)", imported when it runs; `run` and `info` are parsed here
# (so that their --help needs nothing) and run by system_ssp.run_info
COMMANDS = {"thesis": "system_ssp.neighbor.thesis:main", "deorbit-study": "system_ssp.neighbor.deorbit_study:main",
            "mission": "system_ssp.neighbor.mission:main", "replace": "system_ssp.tools.replace:main_replace",
            "compare": "system_ssp.tools.replace:main_compare", "flatten": "system_ssp.tools.flatten:main",
            "convert": "system_ssp.tools.convert:main", "compose": "system_ssp.tools.compose:main",
            "export-fmu": "system_ssp.tools.export_fmu:main", "campaign": "system_ssp.tools.campaign:main",
            "plot": "system_ssp.tools.plot:main", "propulsion": "system_ssp.neighbor.mission:main_propulsion",
            "validation": "system_ssp.neighbor.validation:main", "build": "system_ssp.tools.release:build_main",
            "export": "system_ssp.tools.release:export_main"}
RUN_INFO = "system_ssp.run_info:main"


def command(target):
    """The function a COMMANDS entry names, its module imported now."""
    module, _, function = target.partition(":")
    return getattr(importlib.import_module(module), function)


def _parser():
    ap = ArgumentParser(prog="neighbor-cosim", description="Run SSP 1.0 and 2.0 co-simulations of FMI 2.0 and 3.0 FMUs "
                                 "and the NEIGHBOR applications (python -m system_ssp is the same command).")
    ap.add_argument("--version", action="version", version=f"neighbor-cosim {__version__}")
    sub = ap.add_subparsers(dest="command", required=True)
    r = sub.add_parser("run", help="run a system (.ssp or .ssd), or one FMU alone (.fmu)")
    r.add_argument("path", help="the system (.ssp, an .ssd in its folder, a folder with SystemStructure.ssd, or a "
                   "built system's name, e.g. detumble) or one FMU (.fmu)")
    r.add_argument("--stop-time", type=finite_float, help="seconds (default: the SSD's DefaultExperiment)")
    r.add_argument("--step-size", type=positive_float,
                   help="communication step in s (default: the SSD's master annotation; an nc:Schedule sets its own)")
    r.add_argument("--start-time", type=finite_float, help="seconds (default: the SSD's DefaultExperiment, else 0)")
    r.add_argument("--set", action="append", default=[], metavar="COMP.VAR=VALUE",
                   help="override a parameter or start value (repeatable)")
    r.add_argument("--ssv", action="append", default=[], metavar="FILE",
                   help="extra parameter set, names component.variable (repeatable)")
    r.add_argument("--algorithm", choices=["jacobi", "gauss-seidel"],
                   help="default: the SSD's master annotation, else gauss-seidel")
    r.add_argument("--order", help="Gauss-Seidel component order, comma-separated (default: the SSD's, else by "
                   "the connections)")
    r.add_argument("--step-multiple", action="append", default=[], metavar="COMP=K",
                   help="step this component every K-th communication step (repeatable)")
    r.add_argument("--stop-when", action="append", default=None, metavar="COMP.VAR",
                   help="Boolean output that stops the run when true (repeatable)")
    r.add_argument("--output", help="results file: .csv (units in <name>.units.json) or .parquet")
    r.add_argument("--outputs", help="signals to record, comma-separated component.variable")
    r.add_argument("--record-every", type=positive_int, default=1, help="record a row every N steps (default 1)")
    r.add_argument("--print-final", action="store_true", help="print all final values")
    r.add_argument("--plot", metavar="FILE", help="also draw the recorded signals: .png, .svg or .html (interactive)")
    r.add_argument("--report", metavar="FILE.html", help="also write a report: outcome, an interactive figure of the "
                   "recorded signals, settings and versions, in one HTML file that needs no network")
    r.add_argument("--no-validate", action="store_true", help="skip the XML schema checks and the FMUs' model "
                   "description checks")
    r.add_argument("--strict", action="store_true", help="refuse an FMU whose model description has any problem "
                   "(by default those that do not change the run are read with a warning)")
    r.add_argument("--no-schedule", action="store_true",
                   help="ignore the system's nc:Schedule and run with the fixed step")
    r.add_argument("--events", metavar="FILE", help="a scenario file (TOML [[event]] tables): at a time or when a "
                   "condition holds, set an input, fault an output (stuck, bias, scale, noise, dropout) or release "
                   "it (docs/master.md, Scenario events)")
    r.add_argument("--real-time", type=positive_float, metavar="FACTOR",
                   help="pace the communication points to wall time: 1 real time, 100 a hundred times faster; "
                   "prints the overruns (points a whole step behind) and the worst lateness")
    r.add_argument("--stop-on-overrun", action="store_true",
                   help="with --real-time: stop at the first overrun (exit 1, rows so far kept as with a failure)")
    r.add_argument("--requirements", metavar="FILE", help="a requirements file (TOML): each check judged "
                   "PASS/FAIL/INCONCLUSIVE/ERROR on the run and printed; exit 1 unless all pass "
                   "(docs/requirements.md)")
    r.add_argument("--junit", metavar="FILE.xml", help="with --requirements: also write the verdicts as JUnit XML")
    r.add_argument("--profile", action="store_true",
                   help="print the wall time of each component's set, doStep and get calls and of the master itself "
                   "(the run takes the Python step loop and the standard FMI calls)")
    add_console_arguments(r)
    i = sub.add_parser("info", help="describe a system (.ssp/.ssd) or an FMU: every variable, where parameters "
                       "are bound")
    i.add_argument("path", help="a system (.ssp, .ssd, or a built system's name) or an FMU (.fmu)")
    i.add_argument("--json", action="store_true", help="the same as JSON, for tools")
    i.add_argument("--no-validate", action="store_true", help="skip the XML schema checks and the FMUs' model "
                   "description checks")
    i.add_argument("--strict", action="store_true", help="refuse an FMU whose model description has any problem")
    add_console_arguments(i, progress=False)
    sub.add_parser("replace", add_help=False, help="replace one component's FMU in a system, checked "
                   "(replace SYSTEM COMPONENT NEW.fmu --out X.ssp)")
    sub.add_parser("compose", add_help=False, help="a system from a system spec (compose SPEC.toml --out X.ssp), or "
                   "the spec of a system (compose --from SYSTEM --out SPEC.toml)")
    sub.add_parser("export-fmu", add_help=False, help="the system as one co-simulation FMU, for tools that import only "
                   "FMUs (export-fmu SYSTEM --out X.fmu [--fmi 2|3])")
    sub.add_parser("compare", add_help=False, help="the interface differences of two FMUs (compare A.fmu B.fmu)")
    sub.add_parser("convert", add_help=False, help="the system in SSP 1.0 or 2.0, for tools that read only one "
                   "(convert SYSTEM --ssp-version 2.0 --out X.ssp)")
    sub.add_parser("flatten", add_help=False, help="the system with its system parameters folded into component "
                   "bindings, for hosts that do not read them (flatten SYSTEM --out X.ssp)")
    sub.add_parser("plot", add_help=False, help="draw signals of a result file against time (plot RESULT "
                   "[SIGNAL ...] [--out FILE.png|.svg|.html])")
    sub.add_parser("campaign", add_help=False, help="a sweep or Monte Carlo campaign on Dask (campaign SPEC.toml "
                   "--out DIR [--workers N] [--scheduler ADDRESS])")
    sub.add_parser("thesis", add_help=False,
                   help="run the NEIGHBOR thesis validation cases and compare with the published numbers")
    sub.add_parser("deorbit-study", add_help=False,
                   help="run the thesis de-orbit lifetime study (3 scenarios, with and without the burn)")
    sub.add_parser("mission", add_help=False,
                   help="run the NEIGHBOR mission from deployment to re-entry and write its figures")
    sub.add_parser("propulsion", add_help=False,
                   help="the propulsion budget (delta-V, propellant, tank, feed lines, assembly mass) from simulated "
                   "maneuvers, beside the thesis")
    sub.add_parser("validation", add_help=False,
                   help="every published thesis number the product reproduces: published, ours, difference, "
                   "tolerance, and the test that guards it")
    sub.add_parser("build", add_help=False,
                   help="build every FMU and pack every system into the build folder (the first command that "
                   "needs them does it too)")
    sub.add_parser("export", add_help=False,
                   help="every FMU, system, compatibility information and reference page as one versioned archive")
    return ap


class Terminated(BaseException):
    """SIGTERM or SIGHUP outside a run (a run stops at its next communication point instead):
    unwinds like Ctrl-C, so temporary folders and half-written files are cleaned up."""

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum


def _terminate(signum, frame):
    raise Terminated(signum)


HANDLERS = {signal.SIGINT: signal.default_int_handler, signal.SIGTERM: _terminate, signal.SIGHUP: _terminate}


def main(argv=None):
    """The command line; returns the exit code (see the module docstring)."""
    argv = sys.argv[1:] if argv is None else list(argv)
    debug = "--log-level=debug" in argv or any(a == "--log-level" and argv[k + 1:k + 2] == ["debug"]
                                                 for k, a in enumerate(argv))
    previous = {}
    try:
        with command_line_spelling():  # messages name options as --algorithm jacobi, not algorithm='jacobi'
            if argv[:1] and argv[0] in COMMANDS:
                function, arguments = command(COMMANDS[argv[0]]), argv[1:]
            else:
                arguments = _parser().parse_args(argv)  # first: --help needs no import
                function = command(RUN_INFO)
            # only now, the command's imports done: a KeyboardInterrupt raised inside an import can be
            # swallowed (a weakref callback's "Exception ignored"), turned into an ImportError (numpy's)
            # or end the process by the signal; until here system_ssp.launch's handler ends it cleanly
            previous = {sig: signal.signal(sig, handler) for sig, handler in HANDLERS.items()}
            return function(arguments)
    except RunInterrupted as exc:
        print(one_line(exc), file=sys.stderr)
        _say_partial(exc)
        return 128 + exc.signal
    except RealTimeOverrun as exc:  # the run is sound, it did not keep the pace asked for
        print(f"stopped: {one_line(exc)}", file=sys.stderr)
        _say_partial(exc)
        return 1
    except SSPError as exc:
        print(f"error: {one_line(exc)}", file=sys.stderr)
        if isinstance(exc, SimulationError):
            _say_partial(exc)
        return 2
    except KeyboardInterrupt:
        print("interrupted (SIGINT)", file=sys.stderr)
        return 130
    except Terminated as exc:
        print(f"interrupted ({signal.Signals(exc.signum).name})", file=sys.stderr)
        return 128 + exc.signum
    except SystemExit as exc:  # argparse's refusal (one line, see ArgumentParser), --help, --version
        return exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 2)
    except BrokenPipeError:  # the reader went away (| head): not an error of ours
        sys.stdout = open(os.devnull, "w")
        return 0
    except OSError as exc:
        if exc.errno != errno.ENAMETOOLONG:
            return _unexpected(exc, debug)
        # a name longer than the file system takes: bad input, wherever the first look at it was
        name = str(exc.filename or "")
        shown = name if len(name) <= 80 else f"{name[:60]}... ({len(name):,} characters)"
        print(f"error: {shown}: the file name is longer than the file system takes (a part of at most "
              f"{_path_limit('PC_NAME_MAX', 255)} bytes, a path of at most {_path_limit('PC_PATH_MAX', 4096)})",
              file=sys.stderr)
        return 2
    except Exception as exc:  # unexpected: one line, the traceback only with --log-level debug
        return _unexpected(exc, debug)
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        release_console()  # main() called from Python: its stderr handler goes with it


def _path_limit(name, default):
    try:
        return os.pathconf("/", name)
    except (AttributeError, OSError, ValueError):  # no pathconf (Windows)
        return default


def _unexpected(exc, debug):
    """Exit 3 for an error no check foresaw: one line, the traceback only with --log-level debug."""
    if debug:
        traceback.print_exc()
    print(f"error: unexpected {type(exc).__name__}: {one_line(exc)} (--log-level debug shows where)",
          file=sys.stderr)
    return 3


def one_line(message: object) -> str:
    """A message as one line: line breaks in it (a file name with a newline, an FMU's multi-line
    log) escaped, so that a script reading the last line of stderr gets all of it."""
    return str(message).replace("\r", "\\r").replace("\n", "\\n")


def _say_partial(exc):
    r = exc.result
    if exc.partial_file is not None:
        rows = f"{len(r.data)} rows to t = {r.stop_time:g} s " if r is not None else ""
        print(f"partial results ({rows}recorded before it stopped): {exc.partial_file}", file=sys.stderr)
    elif exc.partial_note:
        print(f"partial results: {exc.partial_note}", file=sys.stderr)
