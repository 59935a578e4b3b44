"""The outcome of a run, and writing it as CSV."""
from pathlib import Path
from typing import Optional

import numpy as np

from ..atomic import atomic_write
from ..errors import SSPError


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
    """

    def __init__(self, data: np.ndarray, stop_time: float, stop_reason: str, steps: int, final: dict,
                 wall_time: float, start_time: float, step_size: Optional[float], algorithm: str, order: list,
                 messages: dict, modes: Optional[dict] = None, profile: Optional[dict] = None):
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

    @property
    def names(self) -> list:
        return list(self.data.dtype.names[1:])

    def __getitem__(self, name: str) -> np.ndarray:
        return self.data[name]

    def __repr__(self):
        return (f"Result(steps={self.steps}, stop_time={self.stop_time!r}, stop_reason={self.stop_reason!r}, "
                f"signals={len(self.data.dtype.names) - 1}, wall_time={self.wall_time:.3f})")

    def write_csv(self, path) -> None:
        write_csv_atomic(self.data, path)


def write_csv_atomic(data: np.ndarray, path) -> None:
    """Write `data` as CSV (header `time,component.variable,...`; Booleans as 0/1; Reals as their
    shortest round-trip repr) via a temporary file in the same folder, renamed on success."""
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise SSPError(f"output file {path}: folder {folder} does not exist")
    with atomic_write(path, "w", newline="") as f:
        names = data.dtype.names
        f.write(",".join(names) + "\n")
        fmts = ["%d" if data.dtype[n].kind in "iub" else "%s" for n in names]  # %s: shortest repr
        cols = [data[n].astype(np.int64) if data.dtype[n].kind == "b" else data[n] for n in names]
        if len(data):
            table = np.empty(len(data), dtype=[(str(i), c.dtype) for i, c in enumerate(cols)])
            for i, c in enumerate(cols):
                table[str(i)] = c
            np.savetxt(f, table, fmt=fmts, delimiter=",")
