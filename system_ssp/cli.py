"""Command line: `neighbor-cosim` (or `python -m system_ssp`) with the subcommands `run`,
`info`, `compose`, `export-fmu`, `replace`, `compare`, `flatten`, `convert`, `campaign`, `thesis`,
`deorbit-study`, `mission`, `propulsion`, `validation`, `build` and `export`, and `--version`.

Exit codes: 0 done; 1 an application's result is incomplete (mission or de-orbit study without
re-entry, a thesis number out of tolerance), or a run paced with --real-time and
--stop-on-overrun fell behind; 2 bad input or a failed FMU (one line naming the
file and line, component or variable); 3 an unexpected error; 130 interrupted by Ctrl-C (SIGINT),
143 by SIGTERM, 129 by SIGHUP. A run that fails or is interrupted writes what it had recorded to
<output>.partial.csv (the mission and the de-orbit study: <out>.partial/) and says where.
"""
import errno
import json
import os
from pathlib import Path
import signal
import sys
import tempfile
import traceback


from . import __version__, archive
from .neighbor import deorbit_study, mission, thesis, validation
from .tools import campaign, compose, convert, export_fmu, flatten, plot, release, replace
from .tools import requirements as req
from .tools.console import (ArgumentParser, finite_float, positive_float, positive_int,
                            add_console_arguments, console_settings, parse_sets, release_console, system_path)
from .errors import RealTimeOverrun, RunInterrupted, SimulationError, SSPError, command_line_spelling
from .master import System
from .master.plotting import FORMATS as PLOT_FORMATS
from .master.report import run_report
from .master.result import check_output_file
from .atomic import check_output_place, write_text_atomic
from .master.components import unsupported_fmu
from .master.info import system_info
from .ssp import model_description
from .ssp.interface import FmuInterface, describe_fmu
from .ssp.writer import single_fmu_system

APPS = {"thesis": thesis.main, "deorbit-study": deorbit_study.main, "mission": mission.main,
        "replace": replace.main_replace, "compare": replace.main_compare, "flatten": flatten.main,
        "convert": convert.main, "compose": compose.main, "export-fmu": export_fmu.main,
        "campaign": campaign.main, "plot": plot.main,
        "propulsion": mission.main_propulsion, "validation": validation.main, "build": release.build_main,
        "export": release.export_main}


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
                   help="with an nc:Schedule: print wall time per component and for the master itself")
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


def _parse_multiples(items):
    out = {}
    for s in items:
        k, _, v = s.partition("=")
        try:
            out[k.strip()] = int(v)
        except ValueError:
            raise SSPError(f"--step-multiple {s!r}: expected component=integer") from None
    return out


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
    previous = {sig: signal.signal(sig, handler) for sig, handler in HANDLERS.items()}
    try:
        with command_line_spelling():  # messages name options as --algorithm jacobi, not algorithm='jacobi'
            if argv[:1] and argv[0] in APPS:
                return APPS[argv[0]](argv[1:])
            return _run_or_info(argv)
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


def _run_or_info(argv):
    args = _parser().parse_args(argv)
    args.path = system_path(args.path)
    if args.command == "info" and args.path.lower().endswith(".fmu"):
        fmu = FmuInterface.read(args.path)
        print(json.dumps(fmu.as_dict(), indent=1) if args.json else describe_fmu(fmu))
        return 0
    if args.command == "run" and args.plot:
        check_output_place(args.plot, "--plot", PLOT_FORMATS)
    if args.command == "run" and args.report:
        check_output_file(args.report, "--report", (".html",))
    suffix = Path(args.path).suffix.lower()
    if args.command == "run" and suffix not in (".ssp", ".ssd", ".fmu") and not Path(args.path).is_dir():
        raise SSPError(f"{args.path}: expected a system (.ssp, .ssd, a folder with SystemStructure.ssd) or an FMU "
                       "(.fmu) to run")
    with tempfile.TemporaryDirectory(prefix="neighbor_one_fmu_") as tmp:
        path = args.path
        if args.command == "run" and suffix == ".fmu":  # the FMU alone, as a system of one
            archive.extract(args.path, Path(tmp) / "checked", args.path)  # refused naming the user's file
            path = str(single_fmu_system(path, tmp))
            md = model_description.read(args.path, args.path, not args.no_validate, args.strict).md
            refusal = unsupported_fmu(md)
            if refusal:
                raise SSPError(f"{args.path} {refusal}")
            experiment = md.defaultExperiment
            if args.stop_time is None and (experiment is None or experiment.stopTime is None):
                raise SSPError(f"{args.path}: no stop time: pass --stop-time (the FMU has no DefaultExperiment)")
            if args.step_size is None and (experiment is None or experiment.stepSize is None):
                raise SSPError(f"{args.path}: no step size: pass --step-size (the FMU has no DefaultExperiment "
                               "stepSize)")
        return _run(args, path)


def _run(args, path):
    if args.command == "run" and args.stop_on_overrun and args.real_time is None:
        raise SSPError("--stop-on-overrun paces nothing without --real-time FACTOR")
    requirements = _requirements(args) if args.command == "run" else None
    progress = console_settings(args)  # before loading: its warnings (FMUs read leniently) are shown
    with System(path, validate=not args.no_validate, strict=args.strict) as system:
        if args.command == "info":
            print(json.dumps(system_info(system), indent=1, default=str) if args.json else system.info())
            return 0
        if requirements is not None:
            args.outputs = _requirement_outputs(system, requirements, args.outputs)
        result = system.run(
            stop_time=args.stop_time, step_size=args.step_size, start_time=args.start_time,
            parameters=parse_sets(args.set), parameter_sets=args.ssv or None, outputs=args.outputs,
            algorithm=args.algorithm, order=args.order, step_multiples=_parse_multiples(args.step_multiple),
            stop_when=args.stop_when, output_file=args.output, progress=progress,
            record_every=args.record_every, schedule=not args.no_schedule, profile=args.profile,
            real_time=args.real_time, stop_on_overrun=args.stop_on_overrun, events=args.events)
    print(f"stop time:   {result.stop_time:g} s ({result.stop_reason})")
    h = f"h = {result.step_size:g} s" if result.step_size is not None else "steps per nc:Schedule mode"
    print(f"steps:       {result.steps} ({h}, {result.algorithm}, order {' '.join(result.order)})")
    if result.step_size_source and result.step_size_source != "as requested":
        print(f"step size:   {result.step_size:g} s from {result.step_size_source}")
    if result.modes:
        for name, m in result.modes.items():
            print(f"  mode {name}: {m['steps']} steps, {m['simulated_time']:g} s simulated")
    if result.profile:
        prof = result.profile
        print(f"wall time by component (set + doStep + get), of {prof['loop']:.3f} s in the step loop:")
        for name, sec in sorted(prof["components"].items(), key=lambda kv: -kv[1]):
            print(f"  {name:<16} {sec:8.3f} s")
        print(f"  {'(master)':<16} {prof['master']:8.3f} s")
    print(f"wall time:   {result.wall_time:.3f} s")
    for e in result.events:
        print(f"event {e['event']}:     t = {e['t']:g} s: {e['action']}" + (f" ({e['description']})"
                                                                          if e["description"] else ""))
    if result.pacing:
        p = result.pacing
        worst = f", worst lateness {p['worst_lateness_s'] * 1e3:.3g} ms at t = {p['worst_at_s']:g} s" \
            if p["late_points"] else ""
        print(f"real time:   x{p['factor']:g}: {p['overruns']} overruns (points a whole step behind) of "
              f"{p['points']}, {p['late_points']} late{worst}")
    if args.output:
        print(f"results:     {args.output}")
    items = sorted(result.final.items())
    shown = items if args.print_final else items[:10]
    print("final values:" if args.print_final else f"final values (first {len(shown)} of {len(items)}; "
          "--print-final for all):")
    for k, v in shown:
        unit = result.units.get(k)
        print(f"  {k} = {v!r}" + (f" {unit}" if unit and unit != "1" else ""))
    if args.plot:
        print(f"plot:        {result.plot(out=args.plot, title=args.path)}")
    verdicts = None
    if requirements is not None:
        verdicts = req.summary(requirements, req.judge_result(requirements, result), False)
        print(req.table(verdicts))
        if args.junit:
            write_text_atomic(args.junit, req.junit(verdicts, f"run {Path(args.path).name}"))
            print(f"junit:       {args.junit}")
    if args.report:
        settings = {k: v for k, v in vars(args).items() if v not in (None, [], False) and k != "command"}
        write_text_atomic(args.report, run_report(result, f"{Path(args.path).name}: {result.stop_reason}", settings,
                                                  first=[("Requirements", req.html(verdicts))] if verdicts else ()))
        print(f"report:      {args.report}")
    if verdicts is not None and not verdicts["all_passed"]:
        c = verdicts["counts"]
        print("requirements not met: " + ", ".join(f"{c[v]} {v}" for v in req.VERDICTS[1:] if c[v]), file=sys.stderr)
        return 1
    return 0


def _requirements(args):
    """run --requirements FILE [--junit FILE.xml], read and checked before the system is loaded."""
    if args.junit and not args.requirements:
        raise SSPError("--junit writes the verdicts of --requirements FILE: pass it too")
    if not args.requirements:
        return None
    requirements = req.load(args.requirements)
    if args.junit:
        check_output_place(args.junit, "--junit")
    return requirements


def _requirement_outputs(system, requirements, outputs):
    """--outputs with the signals the requirements read through max/min/...; a name the system
    has not, or a check reading one of the run's names it lacks, refused before the run."""
    def known(fn, name):
        try:
            system.split_name(name, "signal")
        except SSPError as exc:
            return str(exc)
        return None

    req.check_names(requirements, False, req.RUN_NAMES, known)
    if outputs is None:
        return None
    listed = [o.strip() for o in outputs.split(",") if o.strip()]
    return ",".join(listed + [n for n in req.signals_read(requirements) if n not in listed])
