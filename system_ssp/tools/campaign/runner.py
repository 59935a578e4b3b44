"""Running a campaign on Dask and keeping its results.

    neighbor-cosim campaign SPEC.toml --out DIR [--workers N] [--scheduler ADDRESS]

Without --scheduler a LocalCluster of N worker processes (default: this machine's cores, one
thread each); with --scheduler any running Dask cluster (dask-jobqueue on SLURM/PBS, Kubernetes,
`dask scheduler` + `dask worker`). The folder DIR holds:

- spec.toml and environment.json: the spec as given and the software versions;
- runs/part-*.parquet: one row per run (run, seed, each swept and dispersed value, each metric,
  status, error, wall_s), written as runs finish (at most every 2 s), so an interrupted campaign
  loses at most the runs in flight; the same spec into the same folder resumes, skipping the
  runs already recorded;
- runs.parquet: all rows in run order, summary.json (success rate, per metric mean, std and
  percentiles, probabilities with 95 % Wilson intervals; also printed) and figures/.

A run that reaches the stop time while none of the system's stop conditions held (a detumble
that never settled) is "incomplete": counted apart, not a success, its stop_time metrics missing.
A run that fails or passes timeout_s is a row with its status and error; a worker process that
dies (an FMU that crashes it) is restarted by its nanny and its run recorded as failed.
"""
from collections import Counter
from html import escape
import json
import logging
import math
import os
from pathlib import Path
import platform
import re
import shutil
import signal
import sys
import tempfile
import threading
import time

import numpy as np

from ... import __version__
from ...atomic import atomic_write, check_output_folder, write_text_atomic
from ...errors import SSPError
from .. import requirements as req
from ...master import System, report
from ...master.plan import RunOptions
from ...master.names import near, split_name
from ...master.planning import make_plan
from ...master.plotting import TIME_UNITS, read_result
from ..console import ArgumentParser, positive_int, run_index, add_console_arguments, console_settings
from .spec import FAULT, load_spec
from . import worker as worker_module
from .worker import run_batch, run_one

FLUSH_SECONDS = 2.0
SCATTER_INPUTS = 6  # inputs drawn against each metric in scatter.png
SERIES = "series"  # keep_timeseries: <out>/series/run-<i>.parquet
JUNIT = "requirements.junit.xml"  # --requirements: the verdicts for CI systems


def _read_rows(out):
    """Every row recorded in out/runs/ (parts in any order)."""
    import pyarrow.parquet as pq

    rows = []
    for part in sorted((out / "runs").glob("part-*.parquet")):
        rows += pq.read_table(part).to_pylist()
    return rows


def _write_rows(path, rows, columns):
    import pyarrow as pa
    import pyarrow.parquet as pq

    table = pa.Table.from_pylist([{c: r.get(c) for c in columns} for r in rows])
    with atomic_write(path, "wb") as f:
        pq.write_table(table, f)


def _columns(spec):
    inputs = [n for n, _ in spec.sweeps] + [c for d in spec.dispersions for c in d.columns] + (
        [FAULT] if spec.faults else [])
    return ["run", "seed"] + inputs + [m.name for m in spec.metrics] + ["status", "error", "wall_s"]


def _prepare_folder(spec, out):
    """Create `out`, or check that it holds the same campaign (resume); store spec and versions."""
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise SSPError(f"--out {out}: exists and is not a folder")
    try:
        (out / "runs").mkdir(parents=True, exist_ok=True)
        if spec.keep_timeseries:
            (out / SERIES).mkdir(exist_ok=True)
    except OSError as exc:
        raise SSPError(f"--out {out}: cannot create it ({exc.strerror or exc})") from None
    stored = out / "spec.toml"
    if stored.is_file() and stored.read_text(encoding="utf-8") != spec.text:
        raise SSPError(f"--out {out}: holds the results of another campaign spec (spec.toml differs): use another "
                       "folder, or the same spec to resume")
    write_text_atomic(stored, spec.text)
    import dask
    import fmpy

    env = {"neighbor_cosim": __version__, "python": platform.python_version(), "numpy": np.__version__,
           "fmpy": fmpy.__version__, "dask": dask.__version__, "platform": platform.platform(),
           "system": str(spec.system)}
    write_text_atomic(out / "environment.json", json.dumps(env, indent=1) + "\n")
    return out


SCHEDULER_TIMEOUT_S = 10.0
SCHEDULER_ADDRESS = re.compile(r"^(?:(?:tcp|tls|ws|wss|ucx)://)?(\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9_.-]+):(\d{1,5})/?$")


def check_scheduler_address(address):
    """A Dask scheduler address as `dask scheduler` prints it: [tcp|tls|ws|wss|ucx://]host:port."""
    match = SCHEDULER_ADDRESS.match(address)
    if match is None or not 0 < int(match.group(2)) < 65536:
        raise SSPError(f"--scheduler {address!r}: expected a Dask scheduler's address, tcp://host:port (as `dask "
                       "scheduler` prints it; port 1-65535)")


def _start_resource_tracker():
    """multiprocessing's resource tracker (a process the workers' start needs) ignores SIGINT and
    SIGTERM but dies of SIGHUP, and its successor then prints tracebacks: it is started here with
    SIGHUP ignored, which it keeps (the runner itself handles SIGHUP like SIGTERM)."""
    from multiprocessing import resource_tracker

    if threading.current_thread() is not threading.main_thread():
        resource_tracker.ensure_running()
        return
    previous = signal.signal(signal.SIGHUP, signal.SIG_IGN)
    try:
        resource_tracker.ensure_running()
    finally:
        signal.signal(signal.SIGHUP, previous)


class _SyncCancelRace(logging.Filter):
    """Drops the one record a Ctrl-C can make dask.distributed log with a traceback: its `sync()`
    (2026.8) answers a KeyboardInterrupt by scheduling a cancel() that reads `future`, and when the
    interrupt comes before the event loop has assigned it, tornado logs the NameError. There was
    no future to cancel, so nothing is lost; the runner says it was interrupted."""

    def filter(self, record):
        exc = record.exc_info[1] if record.exc_info else None
        return not (isinstance(exc, NameError) and "'future'" in str(exc))


SYNC_CANCEL_RACE = _SyncCancelRace()


def _client(workers, scheduler):
    import dask
    from dask.distributed import Client, LocalCluster

    # A task whose worker dies is not retried by Dask (it would crash the next one too; the
    # runner resubmits it once itself), and a worker holds one task at a time, so that a crash
    # takes no queued run with it. The workers' statistical profiler is off: it samples the
    # stack every 10 ms under the GIL, which the models' Python code pays for.
    dask.config.set({"distributed.scheduler.allowed-failures": 0, "distributed.scheduler.worker-saturation": 1.0,
                     "distributed.worker.profile.enabled": False})
    if scheduler:
        check_scheduler_address(scheduler)
        try:
            return Client(scheduler, timeout=SCHEDULER_TIMEOUT_S), None
        except (OSError, TimeoutError) as exc:
            raise SSPError(f"--scheduler {scheduler}: no Dask scheduler answered within {SCHEDULER_TIMEOUT_S:g} s "
                           f"({type(exc).__name__}); start one (dask scheduler) or leave out --scheduler for workers "
                           "on this machine") from None
    n = workers or os.cpu_count() or 1
    # Ctrl-C reaches every process of the terminal's group: the workers ignore it (and SIGTERM,
    # SIGHUP: their preload, worker.dask_setup), so that only this process sees it and shuts them
    # down, without their tracebacks. The cluster's scratch space (Dask's and the extracted
    # systems) is one temporary folder, removed after the cluster closes, also when a worker was killed.
    scratch = tempfile.mkdtemp(prefix="neighbor_campaign_")
    _start_resource_tracker()
    try:
        with dask.config.set({"temporary-directory": scratch}):
            cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0",
                                   local_directory=scratch, preload=[worker_module.__name__])
    except BaseException:
        shutil.rmtree(scratch, ignore_errors=True)
        raise
    cluster.neighbor_scratch = scratch
    return Client(cluster), cluster


def _spec_key(spec, name):
    """Where the spec names `name`: parameters.x, dispersions.x, sweep.x, faults.cases.<case> or
    metrics.<metric>."""
    if name in spec.parameters:
        return f"parameters.{name}"
    owner = next((d.name for d in spec.dispersions if name in d.columns or name in d.also), None)
    if owner is not None:
        return f"dispersions.{owner}"
    if any(n == name for n, _ in spec.sweeps):
        return f"sweep.{name}"
    case = next((c for c, values in (spec.faults.cases.items() if spec.faults else ()) if name in values), None)
    if case is not None:
        return f"faults.cases.{case}"
    metric = next((m.name for m in spec.metrics if m.variable == name), None)
    return f"metrics.{metric}" if metric else None


def check_against_system(spec):
    """Every name and value of the spec checked against its system before the first run: the
    master plans run 0 of every sweep point (parameters, parameter sets, the metrics' and the kept
    signals) as it would run it; schedule modes of duration metrics. SSPError naming the spec
    file, the key and the closest names. Returns {metric: unit or None}."""
    record = spec.recorded()
    with System(spec.system) as system:
        schedule = system.desc.master.schedule
        mode_names = [m.name for m in schedule.modes] if schedule is not None else []
        for m in spec.metrics:
            if m.kind == "duration" and m.mode not in mode_names:
                raise SSPError(f"{spec.path}: metrics.{m.name}: duration:{m.mode}: "
                               + (f"the system has no nc:Schedule mode {m.mode!r}{near(m.mode, mode_names)} (modes: "
                                  f"{', '.join(mode_names)})" if mode_names else "the system has no nc:Schedule"))
        # each sweep point, and each fault case with the first point's draws: a bad name anywhere
        # is refused before any run
        cases = [(point, None) for point in range(len(spec.points))]
        cases += [(0, name) for name in (spec.faults.cases if spec.faults else ())]
        for point, fault in cases:
            _, values = spec.inputs(point * spec.runs)
            if fault is not None:
                values[FAULT] = fault
            options = RunOptions(stop_time=spec.stop_time, step_size=spec.step_size,
                                 parameter_sets=tuple(spec.parameter_sets), parameters=spec.overrides(values),
                                 outputs=record, events=spec.run_events(values))
            try:
                make_plan(system, options)
            except SSPError as exc:
                named = re.search(r"'([^']+)'", str(exc))
                key = _spec_key(spec, named.group(1)) if named else None
                raise SSPError(f"{spec.path}: {key + ': ' if key else ''}{exc}") from None
        units = {}
        in_probabilities = {metric for _, metric, _, _ in spec.probabilities}
        for m in spec.metrics:
            if m.kind in ("final", "min", "max"):
                comp, var = split_name(system.comps, m.variable)
                units[m.name] = system.var_unit(comp, var)
                if comp.vars[var].type == "String" and (m.kind != "final" or m.name in in_probabilities):
                    raise SSPError(f"{spec.path}: metrics.{m.name}: {m.variable} is a String"
                                   + (": min and max take numbers" if m.kind != "final" else
                                      ", which a probability cannot compare with a number"))
            elif m.kind in ("stop_time", "time_when", "time_in", "duration"):
                units[m.name] = "s"
    return units


def run_campaign(spec, out, workers=None, scheduler=None, progress=False, batch=1, requirements=None):
    """Run (or resume) campaign `spec` (a CampaignSpec or a spec path) into folder `out`, `batch`
    runs per Dask task (more for short runs: each task costs a round trip of about 10 ms);
    returns the summary dict. `requirements` (a requirements file or its loaded Requirements):
    the probabilities judged over the runs, in the summary ("requirements"), the report and
    requirements.junit.xml."""
    if isinstance(batch, bool) or not isinstance(batch, int) or batch < 1:
        raise SSPError(f"--batch {batch!r}: expected an integer >= 1")
    from dask.distributed import as_completed

    if not hasattr(spec, "inputs"):
        spec = load_spec(spec)
    units = check_against_system(spec)  # before the folder is touched and before any run
    if requirements is not None and not isinstance(requirements, req.Requirements):
        requirements = req.load(requirements)
    if requirements is not None:
        req.check_names(requirements, True, [m.name for m in spec.metrics])
    out = check_output_folder(out, "--out")
    done = {r["run"] for r in _read_rows(out)} if (out / "runs").is_dir() else set()
    todo = [i for i in range(spec.total_runs) if i not in done]
    client = cluster = None
    if todo:  # a scheduler that does not answer is said before the folder is touched
        client, cluster = _client(workers, scheduler)
    tornado_log = logging.getLogger("tornado.application")
    tornado_log.addFilter(SYNC_CANCEL_RACE)
    try:
        out = _prepare_folder(spec, out)
        columns = _columns(spec)
        if done:
            print(f"resuming {out}: {len(done)} of {spec.total_runs} runs already recorded there are kept, "
                  f"{len(todo)} to run", file=sys.stderr)
        if client is not None:
            print(f"campaign {spec.path}: {spec.total_runs} runs of {spec.system.name} into {out}", file=sys.stderr)
            _run(client, spec, out, todo, columns, progress, as_completed, batch)
    except BaseException:
        # stopped (Ctrl-C, SIGTERM, an error): the scheduler's and nannies' reports of the runs
        # cancelled under them are not news; what finished is kept and the runner says why
        logging.getLogger("distributed").setLevel(logging.CRITICAL + 1)  # off, its CRITICAL "closed comm" too
        raise
    finally:
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()
            shutil.rmtree(cluster.neighbor_scratch, ignore_errors=True)
        tornado_log.removeFilter(SYNC_CANCEL_RACE)
    rows = sorted(_read_rows(out), key=lambda r: r["run"])
    _write_rows(out / "runs.parquet", rows, columns)
    summary = summarize(spec, rows, units)
    summary["resumed_from"] = len(done)
    if requirements is not None:
        summary["requirements"] = req.summary(requirements, req.judge_campaign(requirements, rows, FINISHED), True)
        write_text_atomic(out / JUNIT, req.junit(summary["requirements"], f"campaign {spec.path.name}"))
    write_text_atomic(out / "summary.json", json.dumps(summary, indent=1, default=_json) + "\n")
    figures(spec, rows, out / "figures", units)
    write_text_atomic(out / "report.html", campaign_report(spec, rows, summary, out / SERIES))
    return summary


def campaign_report(spec, rows, s, series_dir=None):
    """report.html of a campaign: the summary table, the metrics' distributions (interactive),
    the commonest errors, the spec and the versions; one file."""
    done = finished(rows)
    stats = [(name, m.get("unit") or "", m["n"], *(f"{m[k]:.6g}" for k in ("mean", "std", "min", "p5", "p50", "p95",
                                                                             "max")))
             for name, m in s["metrics"].items() if "mean" in m]
    summary = [f"<p>{escape(counts(s))}</p>",
               report.table(("metric", "unit", "n", "mean", "std", "min", "p5", "p50", "p95", "max"), stats)]
    if s["probabilities"]:
        summary.append(report.table(("probability", "condition", "p", "95 % interval", "runs"), [
            (name, p["condition"], f"{p['p']:.3f}", f"[{p['ci95'][0]:.3f}, {p['ci95'][1]:.3f}]", f"{p['k']}/{p['n']}")
            for name, p in s["probabilities"].items()]))
    sections = [("Summary", "\n".join(summary))]
    if s.get("requirements"):
        sections.insert(0, ("Requirements", req.html(s["requirements"])))
    numeric = {m.name: [float(r[m.name]) for r in done if isinstance(r[m.name], (int, float))
                        and math.isfinite(float(r[m.name]))] for m in spec.metrics}  # None: an incomplete run's
    numeric = {k: v for k, v in numeric.items() if len(set(v)) > 1}
    if numeric:
        units = {name: m.get("unit") for name, m in s["metrics"].items()}
        sections.append(("Distributions over the finished runs (ok and incomplete)", report.histograms(numeric, units)))
    if spec.keep_timeseries and series_dir is not None:
        kept = envelopes(spec, done, series_dir)
        if kept:
            sections.append(("Envelopes over the runs (5th to 95th percentile, median)", kept))
    if s.get("errors"):
        sections.append(("Commonest errors", report.table(("runs", "error"),
                                                          [(e["runs"], e["error"]) for e in s["errors"]])))
    sections += [("Spec", f"<pre>{escape(spec.text)}</pre>"),
                 ("Versions", report.table(("software", "version"), list(report.versions().items())))]
    return report.page(f"campaign {spec.path.name}: {s['runs']} runs of {spec.system.name}", sections)


def envelopes(spec, ok, series_dir, points=500):
    """Percentile bands of each kept signal over the successful runs' series, on a common time grid
    (a run that ended earlier stops contributing where it ended)."""
    series = [read_result(p) for p in (Path(series_dir) / f"run-{r['run']:06d}.parquet" for r in ok) if p.is_file()]
    signals = list(spec.keep_signals or spec.recorded())
    if not series or not signals:
        return ""
    end = max(float(c["time"][-1]) for c, _ in series)
    grid = np.linspace(0.0, end, points)
    columns, units = {"time": grid}, dict(series[0][1])
    for name in signals:
        curves = np.full((len(series), points), np.nan)
        for k, (c, _) in enumerate(series):
            t = np.asarray(c["time"], dtype=float)
            inside = grid <= t[-1]
            curves[k, inside] = np.interp(grid[inside], t, np.asarray(c[name], dtype=float))
        for q in (5, 50, 95):
            columns[f"{name} p{q}"] = np.nanpercentile(curves, q, axis=0)
            units[f"{name} p{q}"] = units.get(name)
    return report.figure(columns, units, [n for n in columns if n != "time"])


def _run(client, spec, out, todo, columns, progress, as_completed, batch=1):
    """Submit the runs `todo` in tasks of `batch` runs, write their rows as they come. A task
    whose worker died is split: each of its runs is submitted alone, and a run that kills a
    worker alone too is a failed row."""
    series_dir = str(out / SERIES) if spec.keep_timeseries else None

    def submit(runs):
        # the spec goes with each task (a few kB): scattered once, it would be lost with a worker
        # that an FMU crashed, and the retries that need it with it
        return client.submit(run_batch, spec, runs, series_dir, pure=False, key=f"runs-{runs[0]}-{time.time_ns()}")

    futures = {submit(todo[k:k + batch]): tuple(todo[k:k + batch]) for k in range(0, len(todo), batch)}
    buffer, last = [], time.monotonic()
    bar = None
    if progress:
        from tqdm import tqdm
        bar = tqdm(total=spec.total_runs, initial=spec.total_runs - len(todo), unit="run", file=sys.stderr,
                   smoothing=0.0)

    def flush():
        if buffer:
            first = min(r["run"] for r in buffer)
            _write_rows(out / "runs" / f"part-{first:07d}-{time.time_ns()}.parquet", buffer, columns)
            buffer.clear()

    alone = set()  # runs already retried in a task of their own
    try:
        pending = as_completed(futures)
        for fut in pending:
            runs = futures[fut]
            try:
                rows = fut.result()
            except Exception as exc:  # the worker died (KilledWorker) or could not run the task
                retry = [i for i in runs if i not in alone]
                for i in retry:  # alone: a run queued or batched beside the one that crashed gets through
                    alone.add(i)
                    again = submit([i])
                    futures[again] = (i,)
                    pending.add(again)
                rows = [_died(spec, i, exc) for i in runs if i not in retry]
            buffer.extend(rows)
            if bar is not None:
                bar.update(len(rows))
            if time.monotonic() - last > FLUSH_SECONDS:
                flush()
                last = time.monotonic()
    finally:  # also on Ctrl-C: what finished is kept, the rest is cancelled
        flush()
        if bar is not None:
            bar.close()
        client.cancel(list(futures))


def _died(spec, i, exc):
    seed, values = spec.inputs(i)
    return {"run": i, "seed": seed, **values, "status": "failed",
            "error": f"the worker running it died ({type(exc).__name__}: {exc}); an FMU may have crashed its process",
            "wall_s": math.nan}


def _json(x):
    if isinstance(x, float) and not math.isfinite(x):
        return None
    return str(x)


def wilson(k, n, z=1.959963984540054):
    """95 % Wilson score interval of a proportion k/n."""
    if n == 0:
        return (math.nan, math.nan)
    p = k / n
    d = 1 + z * z / n
    c = (p + z * z / (2 * n)) / d
    h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    return (max(0.0, c - h), min(1.0, c + h))


def summarize(spec, rows, units=None):
    """Success rate (the ok runs' share: an incomplete one is not a success), per-metric statistics
    over the finished runs (ok and incomplete, with their unit), probabilities over the same runs (a
    metric an incomplete run lacks, such as its end time, counts as the condition not holding: a
    run that never re-entered does not re-enter within five years)."""
    done = finished(rows)
    s = {"campaign": str(spec.path), "system": str(spec.system), "runs": len(rows),
         "ok": sum(r["status"] == "ok" for r in rows), "incomplete": sum(r["status"] == "incomplete" for r in rows),
         "failed": sum(r["status"] == "failed" for r in rows), "timeout": sum(r["status"] == "timeout" for r in rows),
         "metrics": {}, "probabilities": {}}
    s["success_rate"] = s["ok"] / len(rows) if rows else math.nan
    for m in spec.metrics:
        vals = np.array([r[m.name] for r in done if isinstance(r[m.name], (int, float))], dtype=float)
        vals = vals[np.isfinite(vals)] if vals.size else vals
        if vals.size:
            p5, p50, p95 = np.percentile(vals, [5, 50, 95])
            s["metrics"][m.name] = {"unit": (units or {}).get(m.name), "n": int(vals.size),
                                    "mean": float(vals.mean()), "std": float(vals.std()),
                                    "min": float(vals.min()), "p5": float(p5), "p50": float(p50), "p95": float(p95),
                                    "max": float(vals.max())}
        else:
            values = sorted({str(r[m.name]) for r in done})
            s["metrics"][m.name] = {"n": len(done), "values": values[:20]}
    errors = Counter(r["error"] for r in rows if r["status"] not in FINISHED and r.get("error"))
    s["errors"] = [{"error": e, "runs": n} for e, n in errors.most_common(3)]
    if spec.faults:  # runs per fault case ("none": no fault)
        s["faults"] = dict(sorted(Counter(r.get(FAULT, "none") for r in rows).items()))
    s["min_success"] = spec.min_success
    ops = {"<": np.less, "<=": np.less_equal, ">": np.greater, ">=": np.greater_equal, "==": np.equal}
    for name, metric, op, threshold in spec.probabilities:
        vals = [r[metric] for r in done if r[metric] is not None or r["status"] == "incomplete"]
        k = int(sum(v is not None and bool(ops[op](v, threshold)) for v in vals))
        lo, hi = wilson(k, len(vals))
        s["probabilities"][name] = {"condition": f"{metric} {op} {threshold}", "k": k, "n": len(vals),
                                    "p": k / len(vals) if vals else math.nan, "ci95": [lo, hi]}
    return s


FINISHED = ("ok", "incomplete")  # the runs that ran to their end (the others failed or timed out)


def finished(rows):
    """The rows of the runs that ran to their end: ok, or incomplete (the stop time reached before
    any of the system's stop conditions held)."""
    return [r for r in rows if r["status"] in FINISHED]


def counts(s):
    """'N runs: a ok, b incomplete, c failed, d timed out (success rate x %)' of a summary."""
    incomplete = (f"{s['incomplete']} incomplete (stop time reached before a stop condition held), "
                  if s.get("incomplete") else "")
    return (f"{s['runs']} runs: {s['ok']} ok, {incomplete}{s['failed']} failed, {s['timeout']} timed out "
            f"(success rate {100 * s['success_rate']:.1f} %)")


def table(s):
    lines = [counts(s)]
    for name, m in s["metrics"].items():
        if "mean" in m:
            unit = f" ({m['unit']})" if m.get("unit") else ""
            lines.append(f"  {name + unit:<24} mean {m['mean']:<12.6g} std {m['std']:<11.4g} p5 {m['p5']:<11.6g} "
                         f"p50 {m['p50']:<11.6g} p95 {m['p95']:.6g}")
        else:
            lines.append(f"  {name:<24} {', '.join(m['values'])}")
    for name, p in s["probabilities"].items():
        lines.append(f"  P({p['condition']}) = {p['p']:.3f}  [{p['ci95'][0]:.3f}, {p['ci95'][1]:.3f}] 95 % "
                     f"({p['k']}/{p['n']})  {name}")
    for e in s.get("errors", []):
        lines.append(f"  {e['runs']} run(s) failed with: {e['error']}")
    if s.get("faults"):
        lines.append("  fault cases: " + ", ".join(f"{name} {n}" for name, n in s["faults"].items()))
    return "\n".join(lines)


def failed_campaign(s):
    """Why a finished campaign is a failure (exit 1), or None: no run succeeded, or fewer than
    campaign.min_success."""
    if s["runs"] and s["ok"] == 0 and not s.get("incomplete"):  # incomplete runs: min_success decides
        return "no run succeeded"
    if s.get("min_success") is not None and s["success_rate"] < s["min_success"]:
        return f"success rate {100 * s['success_rate']:.1f} % is below campaign.min_success {s['min_success']:g}"
    return None


def figures(spec, rows, folder, units=None):
    """A histogram per numeric metric that varies, with the probabilities' thresholds; a scatter of
    each metric against the inputs that vary, at most SCATTER_INPUTS per metric (those most
    correlated with it: a campaign of 32 noise seeds would otherwise draw hundreds of panels)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import MaxNLocator

    units = units or {}
    done = finished(rows)
    # None: a metric an incomplete run lacks (drawn as missing)
    metrics = [m.name for m in spec.metrics if done and all(isinstance(r[m.name], (int, float)) or r[m.name] is None
                                                            for r in done) and any(r[m.name] is not None for r in done)]
    inputs = [n for n, _ in spec.sweeps] + [c for d in spec.dispersions for c in d.columns]
    inputs = [n for n in inputs if done and all(isinstance(r[n], (int, float)) for r in done)
              and len({float(r[n]) for r in done}) > 1]
    # a metric that is the same in every run (a budget always spent) has nothing to show
    metrics = [m for m in metrics if len({_number(r[m]) for r in done if math.isfinite(_number(r[m]))}) > 1]
    if not metrics:
        return
    thresholds = {}
    for name, metric, op, value in spec.probabilities:
        thresholds.setdefault(metric, []).append((float(value), f"{name}: {metric} {op} {value:g}"))

    scale = {}  # times in the unit that reads best for the values (a lifetime in years, not 1e8 s)
    for name in metrics:
        unit = units.get(name)
        if unit == "s":
            span = max(abs(_number(r[name])) for r in done if math.isfinite(_number(r[name])))
            unit, factor = next((u, f) for u, f in TIME_UNITS if span >= 2 * f or u == "s")
            scale[name] = (factor, unit)
        else:
            scale[name] = (1.0, unit)

    def label(name):
        unit = scale[name][1] if name in scale else units.get(name)
        return f"{name} ({unit})" if unit else name

    def value(r, name):
        return _number(r[name]) / scale.get(name, (1.0, None))[0]

    folder.mkdir(exist_ok=True)
    for name in metrics:
        vals = [value(r, name) for r in done if math.isfinite(_number(r[name]))]
        if not vals:
            continue
        fig, ax = plt.subplots(figsize=(6, 4))
        ax.hist(vals, bins=min(40, max(5, len(vals) // 5)), color="tab:blue")
        for limit, text in thresholds.get(name, []):
            ax.axvline(limit / scale[name][0], color="tab:red", linestyle="--", linewidth=1, label=text)
        if name in thresholds:
            ax.legend(fontsize=8)
        ax.yaxis.set_major_locator(MaxNLocator(integer=True))  # counts
        ax.ticklabel_format(axis="x", useOffset=False)
        ax.set_xlabel(label(name))
        ax.set_ylabel("runs")
        ax.set_title(f"{name}: {len(vals)} finished runs")
        ax.grid(alpha=0.3)
        _save(fig, folder / f"hist_{_safe(name)}.png")
    if not inputs:
        return
    panels = {}
    for m in metrics:
        y = np.array([_number(r[m]) for r in done])
        score = []
        for x_name in inputs:
            x = np.array([float(r[x_name]) for r in done])
            good = np.isfinite(x) & np.isfinite(y)
            c = np.corrcoef(x[good], y[good])[0, 1] if good.sum() > 2 and np.std(x[good]) and np.std(y[good]) else 0.0
            score.append(abs(c) if math.isfinite(c) else 0.0)
        panels[m] = [inputs[k] for k in np.argsort(score)[::-1][:SCATTER_INPUTS]]
    cols = max(len(v) for v in panels.values())
    fig, axes = plt.subplots(len(metrics), cols, figsize=(3.2 * cols, 2.8 * len(metrics)), squeeze=False)
    for a, m in enumerate(metrics):
        for b in range(cols):
            ax = axes[a][b]
            if b >= len(panels[m]):
                ax.set_visible(False)
                continue
            x = panels[m][b]
            ax.scatter([r[x] for r in done], [value(r, m) for r in done], s=8)
            for limit, _ in thresholds.get(m, []):
                ax.axhline(limit / scale[m][0], color="tab:red", linestyle="--", linewidth=1)
            ax.ticklabel_format(useOffset=False)
            ax.set_xlabel(x, fontsize=8)
            ax.set_ylabel(label(m), fontsize=8)
            ax.grid(alpha=0.3)
    _save(fig, folder / "scatter.png")


def _number(value):
    """A metric's value as a float, NaN where a run lacks it (None)."""
    return math.nan if value is None else float(value)


def _safe(name):
    return "".join(c if c.isalnum() or c in "._-" else "_" for c in name)


def _save(fig, path):
    import matplotlib.pyplot as plt

    fig.tight_layout()
    with atomic_write(path, "wb") as f:
        fig.savefig(f, dpi=100, format="png")
    plt.close(fig)


def rerun(spec, index, out):
    """Run `index` of the campaign alone in this process: the same seed and values (they depend
    on the spec and the index only), its row printed, its series written."""
    if not 0 <= index < spec.total_runs:
        raise SSPError(f"--rerun {index}: the campaign has runs 0 to {spec.total_runs - 1}")
    check_against_system(spec)
    folder = out / "rerun"
    folder.mkdir(parents=True, exist_ok=True)
    row = run_one(spec, index, str(folder))
    for key, value in row.items():
        print(f"  {key} = {value!r}")
    if row["status"] not in FINISHED:
        print(f"run {index} {row['status']}: {row['error']}", file=sys.stderr)
        return 1
    if row["status"] == "incomplete":
        print(f"run {index} incomplete: the stop time was reached before any stop condition held", file=sys.stderr)
    print(f"series: {folder / f'run-{index:06d}.parquet'}")
    return 0


def main(argv=None):
    ap = ArgumentParser(prog="neighbor-cosim campaign", description="Run a parameter sweep or Monte Carlo "
                                 "campaign on Dask (see docs/campaigns.md).")
    ap.add_argument("spec", help="the campaign spec (TOML)")
    ap.add_argument("--out", required=True, help="results folder (the same spec into the same folder resumes)")
    ap.add_argument("--workers", type=positive_int, help="local worker processes (default: the machine's cores)")
    ap.add_argument("--requirements", metavar="FILE", help="a requirements file (TOML): each probability judged "
                    "PASS/FAIL/INCONCLUSIVE/ERROR over the runs, printed, in summary.json, report.html and "
                    f"{JUNIT}; exit 1 unless all pass (docs/requirements.md)")
    ap.add_argument("--scheduler", help="address of a running Dask scheduler (tcp://host:8786) instead")
    ap.add_argument("--batch", type=positive_int, default=1,
                    help="runs per Dask task (default 1; more for runs shorter than a second)")
    ap.add_argument("--rerun", type=run_index, metavar="N",
                    help="run N alone, here, with the values it had in the campaign; its recorded signals (the "
                         "metrics' and keep_timeseries') go to DIR/rerun/run-N.parquet")
    add_console_arguments(ap)
    args = ap.parse_args(argv)
    progress = console_settings(args)
    if args.scheduler is not None:
        check_scheduler_address(args.scheduler)
    spec = load_spec(args.spec)
    if args.rerun is not None:
        return rerun(spec, args.rerun, Path(args.out))
    requirements = req.load(args.requirements) if args.requirements else None
    s = run_campaign(spec, args.out, args.workers, args.scheduler, progress, args.batch, requirements)
    print(table(s))
    if requirements is not None:
        print(req.table(s["requirements"]))
    print(f"results in {args.out} (runs.parquet, summary.json, report.html, figures/"
          f"{', ' + JUNIT if requirements is not None else ''})")
    failure = failed_campaign(s)
    if failure:
        print(f"campaign failed: {failure}", file=sys.stderr)
        return 1
    if requirements is not None and not s["requirements"]["all_passed"]:
        c = s["requirements"]["counts"]
        print("requirements not met: " + ", ".join(f"{c[v]} {v}" for v in req.VERDICTS[1:] if c[v]), file=sys.stderr)
        return 1
    return 0
