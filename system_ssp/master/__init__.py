"""The co-simulation master, split along its seams:

- `system`: `System` (load once: schemas, FMUs, connections) and `simulate`;
- `components`, `connections`, `parameters`, `names`, `graph`: what loading resolves;
- `plan`, `planning`: the caller's `RunOptions` and the frozen `RunPlan` a run follows, built from them;
- `instances`: the run's FMU instances and the prepared value transfers between them;
- `algorithms`: the `Algorithm` protocol; fixed-step (Jacobi, Gauss-Seidel) and scheduled (nc:Schedule) stepping;
- `observers`: the `Observer` base (the caller's observers too, reading values through a `RunView`);
  recording, stop conditions, progress and profiling, called once per macro step;
- `execution`: one run from instantiation to the `Result` (`result`).
"""
from .algorithms import Algorithm
from .observers import Observer, RunView, StepInfo
from .plan import RunOptions
from .result import Result, write_csv_atomic, write_result
from .system import System, simulate

__all__ = ["System", "simulate", "RunOptions", "Result", "Observer", "RunView", "StepInfo", "Algorithm",
           "write_csv_atomic", "write_result"]
