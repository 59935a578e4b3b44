"""Scenario events: actions the master takes during a run, at a time or when a condition holds,
without changing any model (libcosim's scenario files, OpenSVF's fault injection).

A scenario file (TOML; `run --events FILE`, `RunOptions(events=...)`, a campaign spec's
`[[events]]`) lists them:

    [[event]]
    at = 300.0                          # s: at the first communication point at or after it
    fault = "sun_sensor.valid"          # an output, as the inputs it feeds see it
    kind = "dropout"                    # stuck, bias, scale, noise or dropout

    [[event]]
    when = "mission.phase == 4"         # or: the first communication point where this holds
    set = { "guidance.mode" = 4 }       # inputs no connection feeds, tunable parameters

    [[event]]
    at = 900.0
    release = "sun_sensor.valid"        # the output is its own again

Faults act on the value the master passes on from an output (every input it feeds sees it from
that communication point on; the FMU and the recorded column keep its own value, record an
input it feeds to see the faulted one):
- stuck: held at `value`, or at its value when the fault begins;
- bias: plus `value`; scale: times `value`; noise: plus a normal draw of sigma `value` at every
  communication point (`seed`, default the event's number);
- dropout: 0 (false for a Boolean): a dead sensor's output.
Each event acts once, in file order among those due at the same point. The result lists what
happened (`Result.events`: time, event, action)."""
from dataclasses import dataclass
import math
import numbers
from pathlib import Path
import re
import sys
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple

import numpy as np

from ..errors import SSPError
from ..limits import read_text_input
from .expressions import Missing, evaluate, parse_check
from .instances import read_ops
from .names import split_name
from .observers import Observer

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

FAULT_KINDS = ("stuck", "bias", "scale", "noise", "dropout")
EVENT_KEYS = {"at", "when", "set", "fault", "kind", "value", "seed", "release", "description"}
SETTABLE = ("tunable", "discrete", "continuous")  # a parameter's or input's variability that may change in a run


@dataclass(frozen=True)
class Event:
    """One action of a scenario, as read (names not yet resolved against a system)."""
    number: int  # 1-based, in file order
    origin: str  # file:line of its [[event]], or "events[i]"
    at: Optional[float] = None
    when: Optional[str] = None
    sets: Tuple[Tuple[str, Any], ...] = ()
    fault: Optional[str] = None
    kind: Optional[str] = None
    value: Optional[float] = None
    seed: Optional[int] = None
    release: Optional[str] = None
    description: str = ""

    def action(self) -> str:
        """The action in words, for Result.events."""
        if self.fault is not None:
            value = "" if self.value is None else f" {self.value:g}"
            return f"fault {self.fault}: {self.kind}{value}"
        if self.release is not None:
            return f"release {self.release}"
        return "set " + ", ".join(f"{name} = {value!r}" for name, value in self.sets)


def read_events(path: Any) -> List[Event]:
    """The events of a scenario file ([[event]] tables); SSPError naming the file and line."""
    path = Path(path)
    text = read_text_input(path, str(path), "the scenario file", "expected a scenario file (TOML, [[event]] tables)")
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SSPError(f"{path}: not valid TOML: {exc}") from None
    unknown = sorted(set(doc) - {"event"})
    if unknown or not isinstance(doc.get("event"), list) or not doc["event"]:
        raise SSPError(f"{path}: expected [[event]] tables (at or when, and set, fault or release)"
                       + (f"; unknown {', '.join(unknown)}" if unknown else ""))
    lines = [n + 1 for n, line in enumerate(text.splitlines()) if line.strip().startswith("[[event]]")]
    return parse_events(doc["event"], [f"{path}:{n}" for n in lines])


def parse_events(entries: Sequence[Mapping[str, Any]], origins: Sequence[str] = ()) -> List[Event]:
    """Events from their tables (a scenario file's, a campaign spec's `[[events]]`, the API's
    dicts); SSPError naming the event's origin and the key."""
    out: List[Event] = []
    for i, e in enumerate(entries):
        where = origins[i] if i < len(origins) else f"events[{i + 1}]"
        if isinstance(e, Event):
            out.append(e)
            continue
        if not isinstance(e, Mapping):
            raise SSPError(f"{where}: an event is a table (at or when, and set, fault or release)")
        extra = sorted(set(e) - EVENT_KEYS)
        if extra:
            raise SSPError(f"{where}: unknown key(s) {', '.join(extra)} (an event has {', '.join(sorted(EVENT_KEYS))})")
        if ("at" in e) == ("when" in e):
            raise SSPError(f"{where}: an event needs `at` (s) or `when` (a condition), one of them")
        at = None
        if "at" in e:
            at = e["at"]
            if isinstance(at, bool) or not isinstance(at, numbers.Real) or not math.isfinite(at):
                raise SSPError(f"{where}: at = {at!r}: expected a time in s")
            at = float(at)
        when = _when(e, where)
        actions = [k for k in ("set", "fault", "release") if k in e]
        if len(actions) != 1:
            raise SSPError(f"{where}: an event does one of set, fault or release (it has "
                           f"{', '.join(actions) or 'none'})")
        sets: Tuple[Tuple[str, Any], ...] = ()
        if "set" in e:
            if not isinstance(e["set"], Mapping) or not e["set"]:
                raise SSPError(f"{where}: set: expected a table of component.variable = value")
            for name, value in e["set"].items():
                if not isinstance(value, (bool, int, float, str)):
                    raise SSPError(f"{where}: set.{name} = {value!r}: expected a number, true/false or a text")
            sets = tuple(e["set"].items())
        kind, value, seed = _fault_fields(e, where)
        for key in ("fault", "release"):
            if key in e and (not isinstance(e[key], str) or not re.fullmatch(r"[^.\s]+\.\S+", e[key])):
                raise SSPError(f"{where}: {key} = {e[key]!r}: expected an output, component.variable")
        out.append(Event(i + 1, where, at, when, sets, e.get("fault"), kind, value, seed, e.get("release"),
                         str(e.get("description", ""))))
    return out


VALUE_MEANS = {"bias": "the offset", "scale": "the factor", "noise": "the sigma"}


def _fault_fields(e: Mapping[str, Any], where: str) -> Tuple[Optional[str], Optional[float], Optional[int]]:
    """(kind, value, seed) of a fault event (None, None, None for another action)."""
    if "fault" not in e:
        if any(k in e for k in ("kind", "value", "seed")):
            raise SSPError(f"{where}: kind, value and seed belong to a fault")
        return None, None, None
    kind = e.get("kind")
    if kind not in FAULT_KINDS:
        raise SSPError(f"{where}: kind = {kind!r}: expected one of {', '.join(FAULT_KINDS)}")
    value = seed = None
    if "value" in e:
        if kind == "dropout":
            raise SSPError(f"{where}: a dropout takes no value (its output reads 0); a held value is kind = stuck")
        value = e["value"]
        if isinstance(value, bool):
            value = float(value)
        if not isinstance(value, numbers.Real) or not math.isfinite(value):
            raise SSPError(f"{where}: value = {value!r}: expected a number")
        value = float(value)
        if kind == "noise" and value < 0:
            raise SSPError(f"{where}: value = {value:g}: a noise's sigma is >= 0")
    elif kind in VALUE_MEANS:
        raise SSPError(f"{where}: a {kind} fault needs value ({VALUE_MEANS[kind]})")
    if "seed" in e:
        seed = e["seed"]
        if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
            raise SSPError(f"{where}: seed = {seed!r}: expected an integer >= 0")
    return kind, value, seed


def _when(e: Mapping[str, Any], where: str) -> Optional[str]:
    if "when" not in e:
        return None
    if not isinstance(e["when"], str):
        raise SSPError(f"{where}: when = {e['when']!r}: expected a condition, e.g. 'mission.phase == 4'")
    try:
        check = parse_check(e["when"])
    except SSPError as exc:
        raise SSPError(f"{where}: when: {exc}") from None
    bad = [n for n in check.names if n != "t"] + [f"{fn}({n})" for fn, n in check.signals if fn != "final"]
    if bad:
        raise SSPError(f"{where}: when = {e['when']!r}: reads {', '.join(bad)}; a condition reads the current "
                       "values of outputs (comp.var) and t")
    return str(e["when"])


def events_of(source: Any) -> List[Event]:
    """RunOptions.events as Events: a scenario file's path, or a list of event tables/Events."""
    if source is None:
        return []
    if isinstance(source, (str, Path)) or hasattr(source, "__fspath__"):
        return read_events(source)
    if isinstance(source, Mapping) or not isinstance(source, Sequence):
        raise SSPError(f"events = {source!r:.80}: expected a scenario file's path or a list of events")
    return parse_events(list(source))


@dataclass(frozen=True)
class PlannedEvent:
    """An event resolved against the loaded system."""
    event: Event
    targets: Tuple[Tuple[int, str, str, Any], ...] = ()  # set: (component, variable, type, value)
    output: Optional[Tuple[int, str]] = None  # fault or release: (component, output)
    condition: Optional[Any] = None  # when: the parsed check
    condition_signals: Tuple[Tuple[int, str], ...] = ()


def plan_events(system: Any, source: Any) -> Tuple[PlannedEvent, ...]:
    """The events of RunOptions.events checked against the system: names, causality (a set
    changes an input no connection feeds or a tunable parameter; a fault acts on an output that
    feeds an input), types. SSPError naming the event."""
    events = events_of(source)
    fed = {(lk.dst, lk.dst_var) for lk in system.links}
    feeding = {(lk.src, lk.src_var) for lk in system.links}
    faulted: Dict[Tuple[int, str], int] = {}
    out = []
    for ev in events:
        def refuse(text, ev=ev):
            return SSPError(f"{ev.origin}: event {ev.number}: {text}")

        try:
            targets = []
            for name, value in ev.sets:
                comp, var = split_name(system.comps, name, "event's variable")
                v = comp.vars[var]
                if (comp.index, var) in fed:
                    raise refuse(f"set {name}: a connection feeds it (every step overwrites it); fault the output "
                                 "that feeds it instead")
                if v.causality not in ("input", "parameter") or (v.causality == "parameter"
                                                                 and v.variability != "tunable"):
                    raise refuse(f"set {name}: a {v.variability or ''} {v.causality} cannot change during a run "
                                 "(FMI 2.0: inputs and tunable parameters); give it before the run (--set)")
                targets.append((comp.index, var, v.type, _typed(value, v.type, name, refuse)))
            output = None
            acted = ev.fault or ev.release
            if acted is not None:
                name = acted
                comp, var = split_name(system.comps, name, "event's output")
                v = comp.vars[var]
                if v.causality != "output":
                    raise refuse(f"{name} is a {v.causality}; a fault acts on an output (as the inputs it feeds "
                                 "see it)")
                if (comp.index, var) not in feeding:
                    raise refuse(f"{name} feeds no input: a fault there would change nothing")
                if v.type not in ("Real", "Integer", "Boolean", "Enumeration"):
                    raise refuse(f"{name} is a {v.type}; faults act on numbers and Booleans")
                if ev.fault is not None and v.type != "Real" and ev.kind in ("bias", "scale", "noise"):
                    raise refuse(f"a {ev.kind} fault acts on a Real output; {name} is {v.type} (stuck or dropout)")
                if ev.release is not None and (comp.index, var) not in faulted:
                    raise refuse(f"release {name}: no event before it faults it")
                if ev.fault is not None:
                    faulted[(comp.index, var)] = ev.number
                output = (comp.index, var)
            condition, signals = None, []
            if ev.when is not None:
                condition = parse_check(ev.when)
                for _, sig in condition.signals:
                    comp, var = split_name(system.comps, sig, "condition's signal")
                    if comp.vars[var].type not in ("Real", "Integer", "Boolean", "Enumeration"):
                        raise refuse(f"when: {sig} is a {comp.vars[var].type}; a condition reads numbers and Booleans")
                    signals.append((comp.index, var))
        except SSPError as exc:
            if str(exc).startswith(ev.origin):
                raise
            raise refuse(str(exc)) from None
        out.append(PlannedEvent(ev, tuple(targets), output, condition, tuple(signals)))
    return tuple(out)


def _typed(value, vtype, name, refuse):
    if vtype == "Real":
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise refuse(f"set {name} = {value!r}: expected a finite number (it is a Real)")
        return float(value)
    if vtype in ("Integer", "Enumeration"):
        if isinstance(value, bool) or not isinstance(value, int):
            raise refuse(f"set {name} = {value!r}: expected an integer (it is an {vtype})")
        return value
    if vtype == "Boolean":
        if not isinstance(value, bool):
            raise refuse(f"set {name} = {value!r}: expected true or false (it is a Boolean)")
        return value
    if not isinstance(value, str):
        raise refuse(f"set {name} = {value!r}: expected a text (it is a String)")
    return value


class _Fault:
    __slots__ = ("kind", "value", "rng", "held", "noise_t", "noise")

    def __init__(self, kind, value, seed):
        self.kind, self.value = kind, value
        self.rng = np.random.default_rng(seed) if kind == "noise" else None
        self.held = None
        self.noise_t, self.noise = None, 0.0


class ScenarioEvents(Observer):
    """Runs the planned events: checks their time or condition at every communication point
    (first among the observers), sets values, and keeps faulted outputs faulted in the values
    the master passes on, after every read of their component (its getter and stepper wrapped)."""

    def __init__(self, table, planned: Sequence[PlannedEvent]):
        self.table = table
        self.pending = list(planned)
        self.log: List[Dict[str, Any]] = []
        self.active: Dict[Tuple[int, str], _Fault] = {}
        self.slots: Dict[Tuple[int, str], Tuple[Any, int, str]] = {}  # (ci, var) -> (GetOp, position, type)
        for op_list in table.gets:
            for op in op_list:
                for j, var in enumerate(op.names):
                    self.slots[(op.ci, var)] = (op, j, _kind_of(op))
        self.by_comp: Dict[int, List[Tuple[int, str]]] = {}
        for pe in planned:
            if pe.output is not None:
                self.by_comp.setdefault(pe.output[0], [])
                if pe.output not in self.by_comp[pe.output[0]]:
                    self.by_comp[pe.output[0]].append(pe.output)
        self.reads = {}
        for pe in planned:
            if pe.condition_signals:
                self.reads[pe.event.number] = read_ops(table, list(pe.condition_signals))[0]
        self._wrap()

    def _wrap(self):
        """Re-apply the faults of a component after each read of its outputs (the master's get,
        and its batched stepper, which reads them inside the FMU)."""
        table = self.table
        for ci in self.by_comp:
            get, step = table.getters[ci], table.steppers[ci]

            def faulted_get(get=get, ci=ci):
                get()
                self._apply(ci)

            def faulted_step(t, dt, step=step, ci=ci):
                step(t, dt)
                self._apply(ci)

            table.getters[ci], table.steppers[ci] = faulted_get, faulted_step

    def _apply(self, ci):
        t = self.table.t
        for key in self.by_comp[ci]:
            fault = self.active.get(key)
            if fault is None:
                continue
            op, j, kind = self.slots[key]
            raw = op.buf[j]
            if fault.kind == "stuck":
                new = fault.held
            elif fault.kind == "dropout":
                new = 0
            elif fault.kind == "bias":
                new = raw + fault.value
            elif fault.kind == "scale":
                new = raw * fault.value
            else:  # noise: one draw per communication point, however often the outputs are read
                if fault.noise_t != t:
                    fault.noise_t, fault.noise = t, float(fault.rng.normal(0.0, fault.value))
                new = raw + fault.noise
            op.buf[j] = new if kind == "Real" else int(round(new))

    def start(self, info):
        self._due(info)

    def step(self, info):
        if self.pending:
            self._due(info)

    def _due(self, info):
        t = info.t
        for pe in list(self.pending):
            ev = pe.event
            if ev.at is not None:
                if t < ev.at - 1e-9 * max(1.0, abs(ev.at)):
                    continue
            elif not self._holds(pe, t):
                continue
            self.pending.remove(pe)
            self._act(pe, t)

    def _holds(self, pe, t):
        values = {}
        for op in self.reads.get(pe.event.number, ()):
            for name, value in zip(op.names, op.read().tolist()):
                values[name] = value
        try:
            holds, _ = evaluate(pe.condition, {"t": t}.get, lambda fn, name: values.get(name))
        except Missing:
            return False
        return holds

    def _act(self, pe, t):
        ev, table = pe.event, self.table
        for ci, var, vtype, value in pe.targets:
            inst = table.instances[ci]
            vr = [table.system.comps[ci].vars[var].valueReference]
            setter = {"Real": inst.fmu.setReal, "Integer": inst.fmu.setInteger, "Enumeration": inst.fmu.setInteger,
                      "Boolean": inst.fmu.setBoolean, "String": inst.fmu.setString}[vtype]
            table.call(ci, f"fmi2Set{'Integer' if vtype == 'Enumeration' else vtype} (event {ev.number})", setter, vr,
                       [value.encode() if vtype == "String" else value], names=(var,))
        if pe.output is not None:
            ci = pe.output[0]
            if ev.fault is not None:
                op, j, kind = self.slots[pe.output]
                fault = _Fault(ev.kind, ev.value, ev.seed if ev.seed is not None else ev.number)
                if ev.kind == "stuck":
                    raw = op.buf[j] if pe.output not in self.active else self._raw(pe.output)
                    fault.held = ev.value if ev.value is not None else raw
                self.active[pe.output] = fault
                self._apply(ci)
            else:
                self.active.pop(pe.output, None)
                table.getters[ci]()  # its own value again, now
        self.log.append({"t": t, "event": ev.number, "action": ev.action(), "description": ev.description})

    def _raw(self, key):
        """The output's own value, read from its FMU (it is faulted in the buffer)."""
        (op,), _ = read_ops(self.table, [key])
        return op.read().tolist()[0]


def _kind_of(op):
    call = getattr(op, "call", "")
    return {"fmi2GetReal": "Real", "fmi2GetInteger": "Integer", "fmi2GetBoolean": "Boolean"}.get(call, "String")
