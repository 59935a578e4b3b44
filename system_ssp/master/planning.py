"""Turning `System.run`'s `RunOptions` and the SSD's master annotation into a `RunPlan`."""
import math
import numbers
from typing import Any, Optional

from ..errors import SSPError, option
from ..ssp.reader import ANNOTATION_TYPE, CONDITION_CAUSALITIES
from .connections import KIND, RECORDABLE
from .graph import toposort
from .names import near, split_name
from .parameters import collect_parameters
from .events import plan_events
from .plan import ALGORITHMS, PlannedMode, RunOptions, RunPlan, SchedulePlan


# The most communication steps a fixed-step run may take: a day of wall time at the master's
# typical 50 us per step (a step size typed a few orders of magnitude too small is refused with
# its step count instead of running for years).
MAX_STEPS = 2_000_000_000


def _order(system, order, algo):
    names = [c.name for c in system.comps]
    where = "component order"
    if order is None:
        order = system.desc.master.order
        where = f"{system.desc.master.order_origin}: nc:Order"
    if order is not None:
        if isinstance(order, str):
            order = order.replace(",", " ").split()
        order = list(order)
        unknown = [o for o in order if o not in system.by_name]
        dup = sorted({o for o in order if order.count(o) > 1})
        missing = [n for n in names if n not in order]
        if unknown or dup or missing:
            parts = []
            if unknown:
                parts.append("unknown " + ", ".join(f"{u!r}{near(u, names)}" for u in unknown))
            if dup:
                parts.append("listed more than once: " + ", ".join(dup))
            if missing:
                parts.append("missing: " + ", ".join(missing))
            raise SSPError(f"{where} {order}: must name every component exactly once ("
                           + "; ".join(parts) + ")")
        if algo == "gauss-seidel":
            _, cycle = toposort(len(names), system.graph.edges)
            if cycle:  # no order of a feedthrough cycle gives every input this step's value
                raise SSPError(f"{where} {order}: the components form an algebraic loop (direct feedthrough "
                               f"cycle) {system.graph.describe(cycle)}, which no Gauss-Seidel order resolves (use "
                               f"{option('--algorithm jacobi', 'algorithm=' + repr('jacobi'))}, or break the loop)")
        return [system.by_name[o].index for o in order]
    if algo == "gauss-seidel":
        return system.graph.order()
    return list(range(len(system.comps)))


def _multiples(system, step_multiples):
    mult = [1] * len(system.comps)
    sm = dict(system.desc.master.step_multiples)
    sm.update(step_multiples or {})
    for name, k in sm.items():
        if name not in system.by_name:
            raise SSPError(f"step multiple for unknown component {name!r}{near(name, system.by_name)}")
        if isinstance(k, bool) or not isinstance(k, numbers.Integral) or k < 1:
            raise SSPError(f"step multiple of {name!r} must be an integer >= 1, got {k!r}")
        mult[system.by_name[name].index] = int(k)
    return mult


def _stops(system, stop_when):
    stops = []
    for s in (list(system.desc.master.stop_conditions) if stop_when is None else list(stop_when)):
        comp, var = split_name(system.comps, s, "stop condition")
        v = comp.vars[var]
        if v.type != "Boolean":
            raise SSPError(f"stop condition {s!r} must be a Boolean variable, it is {v.type}")
        if v.causality != "output":  # an input or parameter holds what it was given: it stops nothing
            raise SSPError(f"stop condition {s!r} must be an output of its component (its causality is {v.causality})")
        stops.append((comp.index, var))
    return stops


def _recorded(system, outputs):
    if outputs is None and system.desc.master.record:  # nc:Record: what the system says to record
        try:
            return _recorded(system, system.desc.master.record)
        except SSPError as exc:
            raise SSPError(f"{system.desc.master.record_origin}: nc:Record: {exc}") from None
    if outputs is None:
        return [(c.index, v.name) for c in system.comps for v in c.md.modelVariables
                if v.causality in ("input", "output") and v.type in RECORDABLE]
    if isinstance(outputs, str):
        outputs = [o for o in outputs.split(",") if o]
    rec = []
    for o in outputs:
        comp, var = split_name(system.comps, o, "output")
        if comp.vars[var].type not in RECORDABLE:
            raise SSPError(f"output {o!r}: variables of type {comp.vars[var].type} cannot be recorded")
        if (comp.index, var) not in rec:
            rec.append((comp.index, var))
    return rec


def step_size_of(system, requested=None):
    """The communication step and where it comes from, first found of: the caller's, our
    annotation's (nc:Master stepSize), OSP's (libcosim's baseStepSize), OMSimulator's
    (oms:FixedStepMaster stepSize), the FMUs' DefaultExperiment stepSize (the smallest, when they
    differ: no FMU is stepped coarser than it asks)."""
    d, m = system.desc, system.desc.master
    if requested is not None:
        return requested, "as requested"
    if m.step_size is not None:
        return m.step_size, f"nc:Master stepSize at {m.step_size_origin}"
    if m.osp_step_size is not None:
        return m.osp_step_size, f"osp:FixedStepAlgorithm baseStepSize at {m.osp_step_size_origin}"
    if m.oms_step_size is not None:
        return m.oms_step_size, f"oms:FixedStepMaster stepSize at {m.oms_step_size_origin}"
    asked = {}
    for c in system.comps:
        experiment = c.md.defaultExperiment
        if experiment is not None and experiment.stepSize is not None:
            try:
                asked[c.name] = float(experiment.stepSize)
            except ValueError:
                continue
    asked = {name: x for name, x in asked.items() if x > 0 and math.isfinite(x)}
    if asked:
        name = min(asked, key=asked.__getitem__)
        which = "the smallest " if len(set(asked.values())) > 1 else ""
        return asked[name], f"{which}DefaultExperiment stepSize of the FMUs ({name})"
    raise SSPError(f"{d.display}: no step size: pass step_size (CLI --step-size), give one in the "
                   f"{ANNOTATION_TYPE} annotation (nc:Master stepSize), OSP's (osp:FixedStepAlgorithm "
                   "baseStepSize) or OMSimulator's (oms:FixedStepMaster stepSize), or use FMUs whose "
                   "DefaultExperiment has a stepSize")


def make_plan(system: Any, options: Optional[RunOptions] = None) -> RunPlan:
    """The RunPlan of `options` on `system` (a loaded `System`; a field left at None: the SSD's
    own setting)."""
    o = options if options is not None else RunOptions()
    d, m = system.desc, system.desc.master
    start = o.start_time if o.start_time is not None else (d.start_time if d.start_time is not None else 0.0)
    stop = o.stop_time if o.stop_time is not None else d.stop_time
    h, h_source = step_size_of(system, o.step_size)
    if stop is None:
        raise SSPError(f"{d.display}: no stop time: pass stop_time (CLI --stop-time) or set "
                       "ssd:DefaultExperiment stopTime")
    for label, x in (("start time", start), ("stop time", stop), ("step size", h)):
        if isinstance(x, bool) or not isinstance(x, numbers.Real) or not math.isfinite(x):
            raise SSPError(f"{label} must be a finite number, got {x!r}")
    start, stop, h = float(start), float(stop), float(h)
    if h <= 0:
        raise SSPError(f"step size must be positive, got {h}")
    if stop < start:
        raise SSPError(f"stop time {stop} is before start time {start}")
    algo = o.algorithm or m.algorithm or m.osp_algorithm or "gauss-seidel"
    if algo not in ALGORITHMS:
        raise SSPError(f"unknown algorithm {algo!r} (expected one of: {', '.join(ALGORITHMS)})")
    order_idx = _order(system, o.order, algo)
    mult = _multiples(system, o.step_multiples)
    stops = _stops(system, o.stop_when)
    rec = _recorded(system, o.outputs)
    if isinstance(o.record_every, bool) or not isinstance(o.record_every, numbers.Integral) or o.record_every < 1:
        raise SSPError(f"record_every must be an integer >= 1, got {o.record_every!r}")
    n_float = (stop - start) / h
    if not math.isfinite(n_float):
        raise SSPError(f"stop time {stop:g} s: {stop - start:g} s in steps of {h:g} s are more communication steps "
                       f"than can be counted (a run may take at most {MAX_STEPS:,})")
    n_steps = int(round(n_float))
    if abs(n_float - n_steps) > 1e-9 * max(1.0, n_float):
        n_steps = int(math.ceil(n_float))
    params = collect_parameters(system, o.parameter_sets, o.parameters)
    sched = None
    if o.schedule and m.schedule:
        sched = _schedule(system, algo, mult)
    if sched is None and n_steps > MAX_STEPS:
        raise SSPError(f"{stop - start:g} s in steps of {h:g} s are {n_steps:,} communication steps, more than the "
                       f"{MAX_STEPS:,} a run may take (about {n_steps * 50e-6 / 86400:,.0f} days at 50 us per "
                       "step): use a larger step size or a shorter run")
    return RunPlan(start=start, stop=stop, step_size=h, step_size_source=h_source, n_steps=n_steps, algorithm=algo,
                   order=tuple(order_idx), multiples=tuple(mult), stops=tuple(stops), record=tuple(rec), params=params,
                   record_every=int(o.record_every), profile=bool(o.profile), schedule=sched,
                   events=plan_events(system, o.events) if o.events is not None else ())


def _schedule(system, algorithm, multiples):
    """Resolve the SSD's nc:Schedule against the loaded FMUs (names, types, causality)."""
    sched = system.desc.master.schedule
    if algorithm != "gauss-seidel":
        raise SSPError(f"{sched.origin}: nc:Schedule runs with gauss-seidel only, not {algorithm!r}")
    if any(k != 1 for k in multiples):
        raise SSPError(f"{sched.origin}: nc:Schedule sets its own steps; step multiples cannot be combined "
                       "with it")
    names = [c.name for c in system.comps]

    def signal(comp, conn, types, what, origin, causalities=("output",)):
        if comp not in system.by_name:
            raise SSPError(f"{origin}: {what} names unknown component {comp!r}{near(comp, names)}")
        c = system.by_name[comp]
        if conn not in c.vars:
            raise SSPError(f"{origin}: {what} names unknown variable {comp}.{conn}{near(conn, list(c.vars))}")
        v = c.vars[conn]
        if v.causality not in causalities or v.type not in types:
            raise SSPError(f"{origin}: {what} {comp}.{conn} must be {' or '.join(causalities)} of type "
                           f"{' or '.join(types)} (it is a {v.causality} {v.type})")
        return c.index, conn, KIND[v.type]

    modes = []
    for m in sched.modes:
        if m.active is None:
            active = [True] * len(system.comps)
        else:
            unknown = [a for a in m.active if a not in system.by_name]
            if unknown:
                raise SSPError(f"{m.origin}: nc:Mode {m.name!r} active lists unknown component(s) "
                               + ", ".join(f"{u!r}{near(u, names)}" for u in unknown))
            active = [c.name in m.active for c in system.comps]
        conds = tuple(signal(c, v, ("Integer", "Enumeration", "Boolean"), f"nc:When of mode {m.name!r}",
                             m.origin, CONDITION_CAUSALITIES)[:2] + (frozenset(vals),) for c, v, vals in m.conditions)
        mult = [1] * len(system.comps)
        for comp, k in m.every.items():
            if comp not in system.by_name:
                raise SSPError(f"{m.origin}: nc:Mode {m.name!r} every names unknown component "
                               f"{comp!r}{near(comp, names)}")
            if not active[system.by_name[comp].index]:
                raise SSPError(f"{m.origin}: nc:Mode {m.name!r} every names {comp!r}, which is not active "
                               "in that mode")
            mult[system.by_name[comp].index] = k
        modes.append(PlannedMode(mode=m, active=tuple(active), conditions=conds, multiples=tuple(mult)))
    events = tuple(signal(c, v, ("Real",), "nc:NextEvent", sched.origin)[:2] for c, v in sched.events)
    return SchedulePlan(modes=tuple(modes), events=events, origin=sched.origin)
