"""The outcome of a run, and writing it: CSV (RFC 4180, units in a sidecar JSON) or Parquet
(units in the schema metadata)."""
import csv
import json
from pathlib import Path
from typing import Any, Dict, List, Optional, Sequence

import numpy as np

from ..atomic import PathLike, atomic_write, check_output_place, is_stream
from ..errors import SSPError
from .plotting import default_signals, drawable, plot, select, units_path

Units = Dict[str, Optional[str]]  # {column: unit or None}
REACHED_STOP_TIME = "reached stop time"  # the stop reason of a run that ran to its stop time


class Result:
    """Outcome of a run.

    data:        numpy structured array, field 'time' then 'component.variable' fields
                 (float64 for Real, int64 for Integer/Enumeration, bool for Boolean).
    stop_time:   time of the last communication point reached.
    stop_reason: "reached stop time" or "stop condition comp.var at t=... s".
    steps:       number of communication steps taken.
    final:       {'component.variable': value} for every input and output at the end.
    wall_time:   seconds spent in run() (instantiation to freeing).
    modes:       scheduled runs: {mode: {"steps", "simulated_time"}}, else None.
    profile:     profile=True on a scheduled run: {"components": {name: s}, "loop": s, "master": s}.
    units:       {column: unit or None} ("time": "s"; the unit of the FMU's value, None when the
                 FMU and the SSD declare none).
    partial:     True for the rows of a run that failed or was interrupted (err.result).
    step_size_source: where step_size came from ("as requested", "nc:Master stepSize, file:line",
                 OSP's baseStepSize, the FMUs' DefaultExperiment); None for a scheduled run.
    pacing:      a run paced to wall time (`real_time=`): {"factor", "points", "late_points",
                 "overruns", "worst_lateness_s", "worst_at_s", "slept_s", "wall_s" (from the first step to the
                 last point)}, else None.
    events:      the scenario events that acted: [{"t", "event" (its number), "action", "description"}].
    stop_conditions: the stop conditions the run watched ('component.variable' names).
    incomplete:  True when the run watched stop conditions and reached its stop time without one
                 holding (a detumble that never settled, an orbit that never re-entered).
    """

    def __init__(self, data: np.ndarray, stop_time: float, stop_reason: str, steps: int, final: Dict[str, Any],
                 wall_time: float, start_time: float, step_size: Optional[float], algorithm: str, order: List[str],
                 messages: Dict[str, List[str]], modes: Optional[Dict[str, Dict[str, float]]] = None,
                 profile: Optional[Dict[str, Any]] = None, units: Optional[Units] = None,
                 partial: bool = False, step_size_source: Optional[str] = None,
                 stop_conditions: Sequence[str] = (), pacing: Optional[Dict[str, Any]] = None,
                 events: Sequence[Dict[str, Any]] = ()) -> None:
        self.data = data
        self.stop_time = stop_time
        self.stop_reason = stop_reason
        self.steps = steps
        self.final = final
        self.wall_time = wall_time
        self.start_time = start_time
        self.step_size = step_size
        self.algorithm = algorithm
        self.order = order
        self.messages = messages
        self.modes = modes
        self.profile = profile
        self.units = units or {}
        self.partial = partial
        self.step_size_source = step_size_source
        self.stop_conditions = tuple(stop_conditions)
        self.pacing = pacing
        self.events = list(events)

    @property
    def incomplete(self) -> bool:
        return bool(self.stop_conditions) and not self.partial and self.stop_reason == REACHED_STOP_TIME

    @property
    def names(self) -> List[str]:
        return list(self.data.dtype.names or ())[1:]

    def __getitem__(self, name: str) -> np.ndarray:
        return self.data[name]

    def __repr__(self) -> str:
        return (f"Result(steps={self.steps}, stop_time={self.stop_time!r}, stop_reason={self.stop_reason!r}, "
                f"signals={len(self.data.dtype.names or ()) - 1}, wall_time={self.wall_time:.3f})")

    def write_csv(self, path: PathLike) -> None:
        write_csv_atomic(self.data, path, self.units)

    def write(self, path: PathLike) -> None:
        """Write the rows to `path`: Parquet for .parquet, otherwise CSV (see write_result)."""
        write_result(self.data, path, self.units)

    def to_pandas(self) -> Any:
        """The rows as a pandas DataFrame (a `time` column, then one per signal); the units in
        `df.attrs["units"]`."""
        try:
            import pandas as pd
        except ImportError:
            raise SSPError("Result.to_pandas needs pandas (pip install pandas)") from None
        df = pd.DataFrame({name: self.data[name] for name in self.data.dtype.names or ()})
        df.attrs["units"] = {name: self.units.get(name) for name in df.columns}
        return df

    def plot(self, signals: Sequence[str] = (), out: PathLike = "run.png", title: str = "") -> Path:
        """Draw recorded signals (names or globs like "dynamics.q_BN*"; none: all) against time
        into `out`: .png or .svg, or .html for an interactive page in one file. Returns the path."""
        names = list(self.data.dtype.names or ())
        chosen = select(names, list(signals)) if signals else default_signals(drawable(self.data, names),
                                                                              self.units)[0]
        return plot({n: self.data[n] for n in names}, dict(self.units), chosen, out, title)


FORMATS = (".csv", ".parquet")


def check_output_file(path: PathLike, what: str = "output file", formats: Sequence[str] = FORMATS) -> Path:
    """Refuse, before a run starts, an output file the run could not write (atomic.check_output_place)."""
    if Path(path).suffix == "" and formats == FORMATS:
        formats = ()  # no suffix: CSV
    checked = check_output_place(path, what, formats)
    if formats == FORMATS and not is_stream(checked):
        # the partial-results place too (where a run that fails or is stopped keeps its rows):
        # refused now, not after the failure
        partial = check_output_place(partial_path(checked), f"{what}'s partial-results file (the rows of a run "
                                     "that stops early)", formats)
        if checked.suffix.lower() != ".parquet":
            check_output_place(units_path(checked), f"{what}'s units file")
            check_output_place(units_path(partial), f"{what}'s partial-results units file")
    return checked


def partial_path(path: PathLike) -> Path:
    """Where the rows of a failed or interrupted run go: x.csv -> x.partial.csv."""
    path = Path(path)
    if is_stream(path):  # the rows go where the whole run would have gone
        return path
    return path.with_name(f"{path.stem}.partial{path.suffix or '.csv'}")


def write_result(data: np.ndarray, path: PathLike, units: Optional[Units] = None) -> None:
    """Write `data` to `path`: `.parquet` as Parquet, anything else as CSV (write_csv_atomic)."""
    if Path(path).suffix.lower() == ".parquet":
        write_parquet_atomic(data, path, units)
    else:
        write_csv_atomic(data, path, units)


def write_csv_atomic(data: np.ndarray, path: PathLike, units: Optional[Units] = None) -> None:
    """Write `data` as CSV, RFC 4180 (comma-separated, names such as `dcm_BN[1,1]` quoted, CRLF
    line ends): header `time,component.variable,...`, Booleans as 0/1, Reals as their shortest
    round-trip repr. With `units`, the sidecar x.units.json holds {column: unit or null}. Each
    file goes through a temporary file in its folder, renamed on success."""
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise SSPError(f"output file {path}: folder {folder} does not exist")
    names = data.dtype.names or ()
    cols = [data[n].astype(np.int64) if data.dtype[n].kind == "b" else data[n] for n in names]
    with atomic_write(path, "w", newline="") as f:
        w = csv.writer(f)  # the default dialect is RFC 4180's: minimal quoting, CRLF
        w.writerow(names)
        w.writerows(zip(*(c.tolist() for c in cols)))
        # the sidecar before the data file is renamed into place: never data without its units;
        # a stream (FIFO, /dev/null) has no place beside it for one
        if units is not None and not is_stream(path):
            with atomic_write(units_path(path), "w", newline="") as u:
                json.dump({n: units.get(n) for n in names}, u, indent=1)
                u.write("\n")


def write_parquet_atomic(data: np.ndarray, path: PathLike, units: Optional[Units] = None) -> None:
    """Write `data` as Parquet (pyarrow): one column per field, Booleans as bool; each field's
    unit in its metadata (b"unit") and all of them in the schema metadata
    (b"neighbor-cosim.units", JSON {column: unit or null})."""
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        raise SSPError(f"output file {path}: writing Parquet needs pyarrow (pip install pyarrow)") from None
    path = Path(path)
    units = units or {}
    names = data.dtype.names or ()

    def arrow_type(n: str) -> Any:  # a String variable's column (numpy object) as Parquet text
        return pa.string() if data.dtype[n].kind == "O" else pa.from_numpy_dtype(data.dtype[n])

    fields = [pa.field(n, arrow_type(n),
                       metadata={b"unit": unit.encode()} if (unit := units.get(n)) else None) for n in names]
    meta = {b"neighbor-cosim.units": json.dumps({n: units.get(n) for n in names}).encode()}
    table = pa.table([pa.array(data[n].tolist() if data.dtype[n].kind == "O" else data[n], type=arrow_type(n))
                      for n in names], schema=pa.schema(fields, metadata=meta))
    with atomic_write(path, "wb") as f:
        pq.write_table(table, f)
