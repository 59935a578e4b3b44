"""What one run will do: the caller's `RunOptions`, and the `RunPlan` resolved from them and the
SSD's master annotation against the loaded FMUs before the first FMU is instantiated.

`System.run` turns its options into a `RunPlan`; the execution and the algorithms read nothing
else. Components are referred to by their index in `System.comps` (SSD order), variables by name."""
from dataclasses import dataclass, field, fields
from os import PathLike
from types import MappingProxyType
from typing import Any, FrozenSet, Mapping, Optional, Sequence, Tuple, Union

from ..ssp.schedule import ScheduleMode

ALGORITHMS = ("gauss-seidel", "jacobi")

Path_ = Union[str, "PathLike[str]"]


@dataclass(frozen=True)
class RunOptions:
    """What a run should do; every field left at None takes the system's own setting (the SSD's
    DefaultExperiment and the org.neighbor-cosim.master annotation). One options object serves
    any number of runs (`dataclasses.replace(options, stop_time=...)` for a variant).

    - `stop_time`, `step_size`, `start_time`: seconds;
    - `parameters`: {"component.variable" or system parameter: value}, applied after every file;
    - `parameter_sets`: .ssv files (names component.variable), applied after the SSD's bindings;
    - `outputs`: the variables to record ("comp.var" names, or one comma-separated string; None:
      every numeric input and output);
    - `algorithm`: "gauss-seidel" or "jacobi"; `order`: the component order (names);
    - `step_multiples`: {component: k}, stepped every k-th communication step;
    - `stop_when`: Boolean outputs that end the run at the first communication point one is true;
    - `record_every`: record a row every this many steps; `schedule`: False runs a system with an
      nc:Schedule at its fixed step; `profile`: wall time per component in `Result.profile`;
    - `events`: scenario events (a scenario file's path or a list of event tables, see
      system_ssp.master.events): values set and outputs faulted during the run."""
    stop_time: Optional[float] = None
    step_size: Optional[float] = None
    start_time: Optional[float] = None
    parameters: Mapping[str, Any] = field(default_factory=dict)
    parameter_sets: Sequence[Path_] = ()
    outputs: Union[None, str, Sequence[str]] = None
    algorithm: Optional[str] = None
    order: Union[None, str, Sequence[str]] = None
    step_multiples: Mapping[str, int] = field(default_factory=dict)
    stop_when: Optional[Sequence[str]] = None
    record_every: int = 1
    schedule: bool = True
    profile: bool = False
    events: Any = None

    @classmethod
    def field_names(cls) -> Tuple[str, ...]:
        return tuple(f.name for f in fields(cls))


@dataclass(frozen=True, slots=True)
class PlannedMode:
    """A mode of the nc:Schedule, as the file declares it, resolved against the components."""
    mode: ScheduleMode  # what the file says (name, step size, record interval, by name)
    active: Tuple[bool, ...]  # per component: stepped in this mode (else suspended)
    conditions: Tuple[Tuple[int, str, FrozenSet[int]], ...]  # (component, connector, values): all must hold
    multiples: Tuple[int, ...]  # per component: stepped every k-th macro step of the mode (1: every step)


@dataclass(frozen=True, slots=True)
class SchedulePlan:
    """nc:Schedule: the first mode whose conditions hold decides each macro step."""
    modes: Tuple[PlannedMode, ...]  # the last may be unconditional
    events: Tuple[Tuple[int, str], ...]  # ((component, Real output announcing the next event time), ...)
    origin: str  # file:line of the nc:Schedule element, for messages


@dataclass(frozen=True, slots=True)
class RunPlan:
    start: float
    stop: float
    step_size: float  # the fixed step (a scheduled run takes its steps from the schedule)
    n_steps: int  # fixed-step runs: communication steps to reach stop
    algorithm: str  # one of ALGORITHMS
    order: Tuple[int, ...]  # component indices in stepping order (Gauss-Seidel) or SSD order (Jacobi)
    multiples: Tuple[int, ...]  # per component: steps every k-th communication step
    stops: Tuple[Tuple[int, str], ...]  # ((component, Boolean output), ...): stop at the first that is true
    record: Tuple[Tuple[int, str], ...]  # ((component, variable), ...) in result column order
    params: Mapping[Tuple[int, str], Any]  # {(component, variable): value} start values, already converted
    record_every: int
    profile: bool = False
    schedule: Optional[SchedulePlan] = None
    step_size_source: str = "as requested"  # where step_size comes from (the caller, a file and line, the FMUs)
    events: Tuple[Any, ...] = ()  # PlannedEvent (system_ssp.master.events), in file order

    def __post_init__(self) -> None:
        object.__setattr__(self, "params", MappingProxyType(dict(self.params)))
