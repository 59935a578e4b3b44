"""One campaign run, as a Dask worker executes it: the system is loaded once per worker process
and reused by every run the worker gets (no per-run extraction, schema check or compilation);
the run's values come from the spec and its index alone; any failure becomes a row."""
import logging
import math
import os
import signal
from pathlib import Path
import tempfile
import time
from typing import Dict

import numpy as np

from components.environment import space_weather

from ...errors import RunTimedOut, SSPError
from ...master import System, write_result

_SYSTEMS: Dict[str, System] = {}  # system path -> System, for the life of this process


def dask_setup(worker):
    """Run by each local worker process as it starts (the runner's LocalCluster preloads this
    module): Ctrl-C, SIGTERM or SIGHUP sent to the terminal's process group are for the runner,
    which closes the workers itself (and its nannies kill a worker that does not close)."""
    for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        signal.signal(sig, signal.SIG_IGN)
    # its warnings (a run cancelled when the runner stops) are not the user's news; errors are
    logging.getLogger("distributed").setLevel(logging.ERROR)
    # but not a heartbeat that finds the scheduler gone: when the runner stops (Ctrl-C, SIGTERM,
    # SIGHUP) its scheduler may close before this worker is told to, and the worker logged that
    # with a traceback at ERROR (seen once in CI); it closes anyway, and a run it lost is the
    # runner's to report
    logging.getLogger("distributed.worker").addFilter(_not_a_lost_heartbeat)


def _not_a_lost_heartbeat(record):
    return "Failed to communicate with scheduler during heartbeat" not in record.getMessage()


def _scratch():
    """The Dask worker's own folder (removed with the worker, and for a local cluster by the
    runner whatever happened), so that a killed worker leaves no extracted system behind."""
    try:
        from distributed import get_worker
        return get_worker().local_directory
    except (ImportError, ValueError):  # not in a Dask worker (--rerun, tests)
        return None


def _system(path):
    key = str(path)
    if key not in _SYSTEMS:
        _SYSTEMS[key] = System(path, scratch=_scratch())
    return _SYSTEMS[key]


def _solar_activity(values, workdir):
    """Helper `solar_activity`: a copy of the space-weather file with F10.7 scaled by @f107_scale,
    given to the orbit (and any atmosphere) FMU; returns (parameters, files to delete after)."""
    scale = values.get("@f107_scale", 1.0)
    path = os.path.join(workdir, f"neighbor_cssi_{os.getpid()}_x{scale!r}.txt")
    space_weather.scaled_copy(scale, path)
    return {"orbit.space_weather_file": path, "orbit.use_constant_space_weather": False}, [path]


HELPERS = {"solar_activity": _solar_activity}


def metric_values(spec, result):
    """{metric name: value} of a finished run; an incomplete run (its stop conditions never held)
    has no stop_time metric (None): the time it ran to is the campaign's, not the system's."""
    out = {}
    data = result.data
    for m in spec.metrics:
        if m.kind == "stop_time":
            out[m.name] = None if result.incomplete else float(result.stop_time)
        elif m.kind == "stop_reason":
            out[m.name] = result.stop_reason
        elif m.kind == "steps":
            out[m.name] = int(result.steps)
        elif m.kind == "final":
            value = result.final.get(m.variable, data[m.variable][-1] if m.variable in data.dtype.names else None)
            out[m.name] = value.item() if isinstance(value, np.generic) else value
        elif m.kind in ("min", "max"):
            col = data[m.variable].astype(float)
            out[m.name] = float(col.min() if m.kind == "min" else col.max())
        elif m.kind == "duration":  # simulated time in a schedule mode (0 if never in it; NaN: no schedule)
            modes = result.modes
            out[m.name] = math.nan if modes is None else float(modes.get(m.mode, {}).get("simulated_time", 0.0))
        else:
            col = data[m.variable]
            hold = col != 0 if m.equals is None else col == m.equals
            if m.kind == "time_in":  # each recorded row holds until the next: the time true (or equal)
                out[m.name] = float(np.sum(np.diff(data["time"])[hold[:-1]]))
            else:  # time_when: the first recorded time the signal is true or equal; NaN if never
                hit = np.flatnonzero(hold)
                out[m.name] = float(data["time"][hit[0]]) if len(hit) else math.nan
    return out


def run_one(spec, index, series_dir=None):
    """The result row of run `index`: run, seed, the swept and dispersed values (one column each),
    every metric, status, error, wall_s. Status: "ok"; "incomplete" (the run reached the stop time
    while none of the system's stop conditions held: metrics kept, its stop_time metrics missing);
    "failed"; "timeout"."""
    seed, values = spec.inputs(index)
    row = {"run": index, "seed": seed}
    row.update({name: (v.item() if isinstance(v, np.generic) else v) for name, v in values.items()})
    for m in spec.metrics:
        row[m.name] = None
    w0 = time.perf_counter()
    cleanup = []
    try:
        system = _system(spec.system)
        params = spec.overrides(values)
        if spec.helper is not None:
            extra, cleanup = HELPERS[spec.helper](values, tempfile.gettempdir())
            params.update(extra)
        record = list(spec.recorded())
        result = system.run(stop_time=spec.stop_time, step_size=spec.step_size, parameter_sets=spec.parameter_sets,
                            parameters=params, events=spec.run_events(values),
                            outputs=record, timeout=spec.timeout_s)
        row.update(metric_values(spec, result))
        row.update(status="incomplete" if result.incomplete else "ok", error="")
        if series_dir is not None:  # keep_timeseries, or a rerun
            write_result(result.data, Path(series_dir) / f"run-{index:06d}.parquet", result.units)
    except RunTimedOut as exc:
        row.update(status="timeout", error=str(exc))
    except SSPError as exc:
        row.update(status="failed", error=str(exc))
    except Exception as exc:  # a model or master bug: recorded, the campaign goes on
        row.update(status="failed", error=f"unexpected {type(exc).__name__}: {exc}")
    finally:
        for path in cleanup:
            try:
                os.unlink(path)
            except OSError:
                pass
    row["wall_s"] = time.perf_counter() - w0
    return row


def run_batch(spec, runs, series_dir=None):
    """The rows of several runs, one after another in this worker (one Dask task)."""
    return [run_one(spec, i, series_dir) for i in runs]
