"""The nc:Schedule of the master annotation, by name: what a generator writes, what the reader
reads, and what the master resolves against the system's components (master.plan.PlannedMode).

One shape from the file to the plan: a mode is stepped at `step_size` while every `When` holds
(the first matching mode wins); `active` lists the components stepped (None: all), `every` the
ones stepped only every k-th step of the mode.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Mapping, NamedTuple, Optional, Tuple


class When(NamedTuple):
    """nc:When: `component.connector` (an Integer, Enumeration or Boolean) has one of `values`
    (Booleans 0 or 1), in the order the file gives them."""
    component: str
    connector: str
    values: Tuple[int, ...]


@dataclass(frozen=True)
class ScheduleMode:
    """nc:Mode: while every condition holds, step with `step_size`, stepping only `active`."""
    name: str
    step_size: float
    active: Optional[Tuple[str, ...]] = None  # components stepped in this mode (None: all)
    record_every: int = 1  # record a row every this many steps of the mode
    conditions: Tuple[When, ...] = ()  # all must hold; only the last mode may have none
    every: Mapping[str, int] = field(default_factory=dict)  # component -> k: stepped every k-th step
    origin: str = ""  # file:line, for messages (empty when built by a generator)


@dataclass(frozen=True)
class Schedule:
    """nc:Schedule: the modes, tried in order, and the Real outputs announcing the next event time."""
    modes: Tuple[ScheduleMode, ...]
    events: Tuple[Tuple[str, str], ...] = ()  # (component, connector)
    origin: str = ""
