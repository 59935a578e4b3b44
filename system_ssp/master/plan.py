"""What one run will do, resolved against the loaded FMUs before the first FMU is instantiated.

`System.run` turns its arguments and the SSD's master annotation into a `RunPlan`; the
execution and the algorithms read nothing else. Components are referred to by their index in
`System.comps` (SSD order), variables by name."""
from dataclasses import dataclass
from types import MappingProxyType
from typing import Mapping, Optional

ALGORITHMS = ("gauss-seidel", "jacobi")


@dataclass(frozen=True, slots=True)
class ScheduleMode:
    """One nc:Mode of an nc:Schedule: when every condition holds, step with `step_size`."""
    name: str
    step_size: float
    active: tuple  # per component: stepped in this mode (else suspended)
    record_every: int  # record a row every this many macro steps of the mode
    conditions: tuple  # ((component, connector, frozenset of values), ...): all must hold
    multiples: tuple  # per component: stepped every k-th macro step of the mode (1: every step)


@dataclass(frozen=True, slots=True)
class SchedulePlan:
    """nc:Schedule: the first mode whose conditions hold decides each macro step."""
    modes: tuple  # (ScheduleMode, ...); the last may be unconditional
    events: tuple  # ((component, Real output announcing the next event time), ...)
    origin: str  # file:line of the nc:Schedule element, for messages


@dataclass(frozen=True, slots=True)
class RunPlan:
    start: float
    stop: float
    step_size: float  # the fixed step (a scheduled run takes its steps from the schedule)
    n_steps: int  # fixed-step runs: communication steps to reach stop
    algorithm: str  # one of ALGORITHMS
    order: tuple  # component indices in stepping order (Gauss-Seidel) or SSD order (Jacobi)
    multiples: tuple  # per component: steps every k-th communication step
    stops: tuple  # ((component, Boolean output), ...): stop at the first that is true
    record: tuple  # ((component, variable), ...) in result column order
    params: Mapping  # {(component, variable): value} start values, already converted
    record_every: int
    profile: bool = False
    schedule: Optional[SchedulePlan] = None

    def __post_init__(self):
        object.__setattr__(self, "params", MappingProxyType(dict(self.params)))
