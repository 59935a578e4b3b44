"""The co-simulation master, split along its seams:

- `system`: `System` (load once: schemas, FMUs, connections) and `simulate`;
- `components`, `connections`, `parameters`, `names`, `graph`: what loading resolves;
- `plan`, `planning`: the frozen `RunPlan` a run follows, built from the arguments;
- `instances`: the run's FMU instances and the prepared value transfers between them;
- `algorithms`: fixed-step (Jacobi, Gauss-Seidel) and scheduled (nc:Schedule) stepping;
- `observers`: recording, stop conditions, progress and profiling, called once per macro step;
- `execution`: one run from instantiation to the `Result` (`result`).
"""
from .result import Result, write_csv_atomic, write_result
from .system import System, simulate

__all__ = ["System", "simulate", "Result", "write_csv_atomic", "write_result"]
