"""The `run` and `info` subcommands of `neighbor-cosim` (their options: system_ssp.cli): a system
or one FMU loaded and run, its outcome printed, written, drawn, reported and judged; a system or
FMU described. Imported when one of them runs (the command line's other work needs none of it)."""
import json
from pathlib import Path
import sys
import tempfile

from . import archive
from .atomic import check_output_place, write_text_atomic
from .errors import SSPError
from .master import System
from .master.components import unsupported_fmu
from .master.info import system_info
from .master.observers import profile_table
from .master.plotting import FORMATS as PLOT_FORMATS
from .master.report import run_report
from .master.result import check_output_file
from .ssp import model_description
from .ssp.interface import FmuInterface, describe_fmu
from .ssp.writer import single_fmu_system
from .tools import requirements as req
from .tools.console import console_settings, parse_sets, system_path


def _parse_multiples(items):
    out = {}
    for s in items:
        k, _, v = s.partition("=")
        try:
            out[k.strip()] = int(v)
        except ValueError:
            raise SSPError(f"--step-multiple {s!r}: expected component=integer") from None
    return out


def main(args):
    """`run` or `info` with their parsed options; the exit code."""
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
        print(profile_table(result.profile))
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
