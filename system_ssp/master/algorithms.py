"""The master algorithms, over one `InstanceTable`: fixed-step (Jacobi or Gauss-Seidel, with
step multiples) and scheduled (Gauss-Seidel with mode-dependent steps, nc:Schedule).

An algorithm fills a `StepInfo`: `start` after initialization; `run` steps until the stop time or
a stop condition and calls the observers after every macro step; `finish` at the end;
`refresh_for_record` brings the values a recorded row shows up to date."""
import ctypes
import math
import os
import sys
import time
from typing import Callable, Dict, List, Optional, Protocol, Sequence

import numpy as np

from ..errors import SimulationError
from .connections import KIND
from .instances import CTYPE, GET, StepFailed
from .observers import StepInfo

# The compiled loop returns to Python after at most this many steps, and sooner where steps are
# slow: each span is sized to take about SPAN_SECONDS of wall time, so that the observers (an
# interruption, the wall-clock limit, the progress bar) see the run that often
SPAN_STEPS = 2000
SPAN_SECONDS = 0.05


class SpanSize:
    """The steps the next span may take: doubled while spans take under half SPAN_SECONDS,
    halved when one took over twice that."""

    def __init__(self):
        self.steps = min(16, SPAN_STEPS)
        self.t0 = 0.0

    def start(self):
        self.t0 = time.perf_counter()
        return self.steps

    def took(self):
        spent = time.perf_counter() - self.t0
        if spent < 0.5 * SPAN_SECONDS:
            self.steps = min(2 * self.steps, SPAN_STEPS)
        elif spent > 2.0 * SPAN_SECONDS:
            self.steps = max(1, self.steps // 2)

# A run of fewer steps keeps the Python loop, unless numba is in the process already: importing numba
# and loading the compiled loop's functions from its cache (about a second here) costs more than the
# compiled loop saves on such a run (about 10 us a step of the detumble system). The two loops give
# the same results bit for bit; NEIGHBOR_COSIM_COMPILED_LOOP=1 takes the compiled one for every run
# it can serve, =0 for none.
SHORT_RUN_STEPS = 50_000


def compiled_loop(table, rows, steps: float):
    """system_ssp.master.compiled (numba imported with it) when its loop can serve the run of the
    table's components recording `rows` and repays its loading for `steps` macro steps, else None."""
    choice = os.environ.get("NEIGHBOR_COSIM_COMPILED_LOOP", "")
    if choice == "0" or (choice != "1" and steps < SHORT_RUN_STEPS and "numba" not in sys.modules):
        return None
    from . import compiled

    return compiled if compiled.eligible(table, range(len(table.instances)), rows) else None


Stepper = Callable[[float, float], None]  # (t, h): set a component's inputs, doStep, get its outputs


class Algorithm(Protocol):
    """What the execution asks of a master algorithm (FixedStepAlgorithm, ScheduledAlgorithm)."""

    steppers: List[Stepper]  # per component, in SSD order (a profiler may wrap them)

    def compile(self, stop_ops: Sequence, rows) -> bool:
        """Take the steps in the compiled loop (system_ssp.master.compiled) when it can serve the
        run; `stop_ops` are the stop conditions' reads, `rows` the Recorder, whose rows the loop
        records on the way. False: the Python loop only."""

    def start(self, info: StepInfo) -> None:
        """After initialization: set the start time and the recording interval in `info`."""

    def run(self, info: StepInfo, observe: Sequence[Callable[[StepInfo], None]]) -> None:
        """Step until the stop time or until `info.fired`, calling `observe` after every macro step."""

    def refresh_for_record(self) -> None:
        """Bring the values a recorded row shows up to date."""

    def finish(self, info: StepInfo) -> None:
        """After the last step (the inputs set as they stand at the end)."""

    def statistics(self) -> Optional[Dict[str, Dict[str, float]]]:
        """Per schedule mode: steps and simulated time; None for a fixed-step run."""


class FixedStepAlgorithm:
    """Fixed communication step h, t_n = start + n h from an integer counter; the last step is
    shortened to end exactly at the stop time.

    - Jacobi: every component steps from the same input values (outputs of the previous
      communication point), then every output is read; the inputs for the next step are set
      after the observers saw the step (libcosim's fixed-step algorithm).
    - Gauss-Seidel: components step in `plan.order`, each seeing the outputs of those already
      stepped; then inputs are propagated once more in order (no doStep), so direct-feedthrough
      outputs reflect t + h before recording and stop conditions.
    - Step multiples k: a component steps only every k-th communication step, by k h."""

    def __init__(self, table, plan):
        self.table = table
        self.plan = plan
        self.order = list(plan.order)
        self.mult = list(plan.multiples)
        self.all_one = all(k == 1 for k in self.mult)
        self.jacobi = plan.algorithm == "jacobi"
        self.n = len(table.instances)
        self.steppers = list(table.steppers)  # per component: set, doStep, get (a profiler may wrap them)

        self.loop = self.compiled = None  # the compiled loop and its module, when compile() takes it

    def compile(self, stop_ops, rows):
        compiled = compiled_loop(self.table, rows, self.plan.n_steps)
        if compiled is None:
            return False
        self.compiled = compiled
        self.loop, self.span = compiled.Loop(self.table, rows, stop_ops=stop_ops), SpanSize()
        self.order_array, self.mult_array = np.array(self.order, dtype=np.int64), np.array(self.mult, dtype=np.int64)
        self.span_function = compiled.jacobi_span if self.jacobi else compiled.fixed_span
        self.loop.load(fixed=(self.order_array, self.mult_array), span=self.span_function)
        return True

    def start(self, info):
        self.table.t = info.t = self.plan.start
        info.record_every = self.plan.record_every

    def _transfer(self, k):
        """Jacobi: set the inputs for step k of every component due then (and all at the end)."""
        N, mult, setters = self.plan.n_steps, self.mult, self.table.setters
        for ci in range(self.n):
            if self.all_one or k % mult[ci] == 0 or k >= N:
                setters[ci]()

    def run(self, info, observe):
        """Step until the stop time or a stop condition, calling `observe` (the observers' step
        functions) after every communication step."""
        p, table = self.plan, self.table
        start, stop, h, N = p.start, p.stop, p.step_size, p.n_steps
        mult, all_one, n, order = self.mult, self.all_one, self.n, self.order
        do_steps, steppers = table.do_steps, self.steppers
        setters, getters, has_ft = table.setters, table.getters, table.has_ft
        jacobi = self.jacobi
        loop = self.loop
        while info.fired is None and info.steps < N:
            if loop is not None:
                self._span(info, loop, observe)
                continue
            k = info.steps
            t = start + k * h
            table.t = t
            if jacobi:
                if k > 0:
                    self._transfer(k)
                for ci in range(n):
                    mk = mult[ci]
                    if all_one or k % mk == 0:
                        # The nominal step, not a difference of rounded times: models that
                        # integrate with the step (the thesis' Euler scripts) must see exactly h.
                        do_steps[ci](t, mk * h if k + mk < N else stop - t)
                for get in getters:
                    get()
            else:
                for ci in order:
                    mk = mult[ci]
                    if all_one or k % mk == 0:
                        steppers[ci](t, mk * h if k + mk < N else stop - t)
                for ci in order:
                    setters[ci]()
                    if has_ft[ci]:
                        getters[ci]()
            k += 1
            info.steps = k
            info.t = table.t = start + k * h if k < N else stop
            info.last = k == N
            for f in observe:
                f(info)

    def _span(self, info, loop, observe):
        """A span of steps in the compiled loop (rows recorded on the way), then the observers
        once, on its last step."""
        p, table = self.plan, self.table
        k0, N = info.steps, p.n_steps
        rows, times = loop.enter(info.record_every)
        steps, flags = self.span_function(loop.T, self.order_array, self.mult_array, bool(self.all_one),
                                          float(p.start), float(p.stop), float(p.step_size), int(N), int(k0),
                                          self.span.start(), loop.changed, loop.status, rows, times, loop.rec)
        self.span.took()
        loop.leave()
        k = k0 + steps
        if flags & self.compiled.FAILED:
            table.t = info.t = p.start + k * p.step_size  # the step that failed
            raise loop.failure()
        info.steps = k
        info.t = table.t = p.start + k * p.step_size if k < N else p.stop
        info.last = k == N
        for f in observe:
            f(info)

    def refresh_for_record(self):
        pass

    def finish(self, info):
        if self.jacobi and info.steps > 0:
            self._transfer(info.steps)

    def statistics(self):
        return None


class _Mode:
    """A schedule mode prepared for the loop."""
    __slots__ = ("name", "h", "order", "record_every", "conditions", "mult", "refresh", "arrays")

    def __init__(self, name, h, order, record_every, conditions, mult, refresh):
        self.name, self.h, self.order, self.record_every = name, h, order, record_every
        self.conditions, self.mult, self.refresh = conditions, mult, refresh
        self.arrays = None  # (order, mult, refresh, compiled.LazyRefresh) for the compiled loop


class _Signal:
    """One scalar output read straight through the FMI functions (schedule conditions, events)."""
    __slots__ = ("fn", "c", "vr", "buf", "ci", "name", "var", "call")

    def __init__(self, table, ci, var, kind):
        comps = table.system.comps
        self.vr = (ctypes.c_uint * 1)(comps[ci].vars[var].valueReference)
        self.buf = (CTYPE[kind] * 1)()
        self.fn = table.instances[ci].function(GET[kind], self.vr, 1)
        self.c = table.instances[ci].fmu.component
        self.ci = ci
        self.name = f"{comps[ci].name}.{var}"
        self.var, self.call = var, GET[kind]

    def read(self):
        s = self.fn(self.c, self.vr, 1, self.buf)
        if s > 1:
            raise StepFailed(self.ci, self.call, s, (self.var,))
        return self.buf[0]


class ScheduledAlgorithm:
    """Gauss-Seidel with mode-dependent communication steps (nc:Schedule).

    After initialization and after every macro step the algorithm reads the schedule's condition
    signals and takes the first mode whose conditions all hold. The next macro step [t, t + h] is
    that mode's step size, shortened so that it ends exactly on the earliest nc:NextEvent time
    ahead (an FMU announcing e.g. a timer expiry) and on the stop time. Each component keeps its
    own time t_c:
    - active, every = 1: stepped from t_c to t + h (t_c = t, or a little before when it ran
      ahead in an earlier mode; communication points stay contiguous);
    - active, every = k > 1 (nc:Mode every="comp:k"): stepped when due (t_c <= t) from t_c to
      t + k stepSize, i.e. ahead of the master by k stepSize with its inputs held from t (like
      fixed-step multiples); until the master reaches t_c it is not stepped again;
    - not active in the mode: suspended, not stepped, outputs held, inputs not set. When it
      becomes active again its clock jumps to the current time: its next doStep starts there,
      and the suspended span is skipped, not integrated (our runtime's FMUs, which refuse a doStep
      that does not start where the last one ended, are told so: InstanceTable.resume; every
      component must declare canHandleVariableCommunicationStepSize).
    After the steps, direct-feedthrough components whose outputs the schedule or a stop condition
    watches, or that feed a component stepping before them, get their inputs again and their
    outputs are read (so conditions, stop signals and the next steps see values at t + h); the
    rest is brought up to date on recorded rows (every active component), and inputs are always
    set right before a doStep. Rows are recorded every `recordEvery` macro steps of a mode, at
    every mode change, at a stop condition and at the end."""

    def __init__(self, table, plan):
        self.table = table
        self.plan = plan
        sch = plan.schedule
        comps = table.system.comps
        n = self.n = len(table.instances)
        for ci in range(n):
            cs = comps[ci].md.coSimulation
            if cs is not None and not cs.canHandleVariableCommunicationStepSize:
                raise SimulationError(f"{sch.origin}: component {comps[ci].name!r} cannot handle a variable "
                                      "communication step size, which nc:Schedule needs")
        consumers = [set() for _ in range(n)]
        producers = [set() for _ in range(n)]
        for lk in table.system.links:
            consumers[lk.src].add(lk.dst)
            producers[lk.dst].add(lk.src)
        watched = {ci for ci, _ in plan.stops} | {ci for ci, _ in sch.events}
        watched |= {ci for m in sch.modes for ci, _, _ in m.conditions}
        has_ft = table.has_ft

        def refreshed(order):
            """Feedthrough components whose outputs must be brought to t + h after the steps:
            those watched by the schedule or a stop condition, those read by a component that
            steps before them, and (transitively) their feedthrough producers. The others are
            read fresh in the next step pass anyway."""
            pos = {ci: k for k, ci in enumerate(order)}
            need = {ci for ci in order if has_ft[ci]
                    and (ci in watched or any(cj in pos and pos[cj] < pos[ci] for cj in consumers[ci]))}
            grow = list(need)
            while grow:
                for cj in producers[grow.pop()]:
                    if cj in pos and has_ft[cj] and cj not in need:
                        need.add(cj)
                        grow.append(cj)
            return [ci for ci in order if ci in need]

        # Each condition signal is read once per pick, and only when its component stepped or was
        # refreshed since the last read (a read is an FMI call); modes test the values held here.
        self.signals, index = [], {}
        for m in sch.modes:
            for ci, var, _ in m.conditions:
                if (ci, var) not in index:
                    index[(ci, var)] = len(self.signals)
                    self.signals.append(_Signal(table, ci, var, KIND[comps[ci].vars[var].type]))
        self.signal_values = [0] * len(self.signals)
        self.modes = []
        for m in sch.modes:
            conds = [(index[(ci, var)], vals) for ci, var, vals in m.conditions]
            order = [ci for ci in plan.order if m.active[ci]]
            self.modes.append(_Mode(m.mode.name, m.mode.step_size, order, m.mode.record_every, conds, list(m.multiples),
                                    refreshed(order)))
        self.events = [_Signal(table, ci, var, "Real") for ci, var in sch.events]
        self.cond_comps = sorted({sig.ci for sig in self.signals})
        self.prod = [sorted(producers[ci]) for ci in range(n)]
        self.consumers, self.watched = consumers, watched  # for the compiled loop's lazy refresh
        # Times closer than this are the same instant: a few ulps of the largest time in the run
        # (1.5e-5 s at 40 years), far below any step, so that t + (t_event - t) lands on t_event.
        self.tol = 64.0 * math.ulp(max(1.0, abs(plan.start), abs(plan.stop)))
        self.steppers = list(table.steppers)  # per component: set, doStep, get (a profiler may wrap them)
        self.mode_time = {m.name: 0.0 for m in self.modes}
        self.mode_steps = {m.name: 0 for m in self.modes}
        self.loop = self.compiled = None  # the compiled loop and its module, when compile() takes it

    def compile(self, stop_ops, rows):
        shortest = min(m.h for m in self.modes)  # the most steps the run may take
        compiled = compiled_loop(self.table, rows, (self.plan.stop - self.plan.start) / shortest)
        if compiled is None:
            return False
        self.compiled = compiled
        self.loop = compiled.Loop(self.table, rows, self.signals, self.events, stop_ops, self.prod)
        self.span = SpanSize()
        for m in self.modes:
            m.arrays = (np.array(m.order, dtype=np.int64), np.array(m.mult, dtype=np.int64),
                        np.array(m.refresh, dtype=np.int64),
                        compiled.lazy_refresh(self.n, m.order, m.refresh, self.consumers, self.watched))
        self.loop.load(mode_arrays=self.modes[0].arrays)
        return True

    def _pick(self, changed=None):
        """The first mode whose conditions hold, the signals of the components in `changed` (all
        when None) read again."""
        values = self.signal_values
        for j, sig in enumerate(self.signals):
            if changed is None or changed[sig.ci]:
                values[j] = int(sig.read())
        return self._choose()

    def _choose(self):
        """The first mode whose conditions hold for the signal values held."""
        values = self.signal_values
        for mode in self.modes:
            for j, vals in mode.conditions:
                if values[j] not in vals:
                    break
            else:
                return mode
        raise SimulationError(f"{self.plan.schedule.origin}: no nc:Mode matches at t={self.table.t:g} s ("
                              + ", ".join(f"{sig.name}={values[j]}" for j, sig in enumerate(self.signals))
                              + "); end the schedule with an unconditional nc:Mode")

    def start(self, info):
        start = self.plan.start
        self.t = self.table.t = info.t = start
        self.tc = [start] * self.n  # each component's own time
        self.mode = self._pick()
        self.next_mode = self.mode
        self.active_order = self.mode.order
        active = set(self.active_order)
        self.suspended = [ci not in active for ci in range(self.n)]
        self.ev_values = [sig.read() for sig in self.events]
        info.record_every = self.mode.record_every
        info.mode = self.mode.name

    def run(self, info, observe):
        """Step until the stop time or a stop condition, calling `observe` (the observers' step
        functions) after every macro step."""
        end = self.plan.stop - self.tol
        advance, loop = self._advance, self.loop
        while info.fired is None and self.t < end:
            if loop is None:
                advance(info)
            else:
                self._span(info, loop)  # the observers see the span's last step
            for f in observe:
                f(info)

    def _span(self, info, loop):
        """Steps of the next mode in the compiled loop (what _advance does, step by step, rows
        recorded on the way) until a condition signal's change, a stop signal, the end or the
        span's size."""
        table, tol, stop = self.table, self.tol, self.plan.stop
        mode = self.mode = self.next_mode
        self.active_order = mode.order
        t, tc, suspended = self.t, self.tc, self.suspended
        for ci in mode.order:
            if suspended[ci]:
                tc[ci] = t  # back from suspension: the clock jumps to now
                table.resume(ci, t)
                suspended[ci] = False
        T = loop.T
        T.ev_buf[:] = self.ev_values
        T.sig_values[:] = self.signal_values
        clocks = np.array(tc, dtype=np.float64)
        order, mult, refresh, lazy = mode.arrays
        rows, times = loop.enter(mode.record_every)
        compiled = self.compiled
        steps, t1, spent, flags = compiled.scheduled_span(
            T, lazy, order, mult, refresh, float(mode.h), float(t), float(stop), float(tol), self.span.start(),
            float(self.mode_time[mode.name]), clocks, loop.changed, loop.status, rows, times, loop.rec)
        self.span.took()
        loop.leave()
        self.tc = clocks.tolist()
        self.ev_values = T.ev_buf.tolist()
        self.signal_values = T.sig_values.tolist()
        self.mode_time[mode.name] = spent
        self.mode_steps[mode.name] += steps
        self.t = table.t = t1
        info.steps += steps
        if flags & compiled.FAILED:
            raise loop.failure()
        self._next(info, mode, self._choose() if flags & compiled.CONDITION_CHANGED else mode,
                   loop.changed.tolist(), t1)

    def _advance(self, info):
        table, tol, stop = self.table, self.tol, self.plan.stop
        mode = self.mode = self.next_mode
        order, mult, h_mode = mode.order, mode.mult, mode.h
        self.active_order = order
        t = self.t
        h = h_mode
        for te in self.ev_values:
            if te > t + tol and te - t < h:
                h = te - t
        if stop - t < h + tol:
            h = stop - t
        t1 = t + h if stop - (t + h) > tol else stop
        changed = [False] * self.n
        tc, suspended, steppers = self.tc, self.suspended, self.steppers
        for ci in order:
            if suspended[ci]:
                tc[ci] = t  # back from suspension: the clock jumps to now
                table.resume(ci, t)
                suspended[ci] = False
            t_c = tc[ci]
            if t_c > t + tol:
                continue  # ahead of the master (stepped with a multiple)
            k = mult[ci]
            end = t1 if k == 1 else min(t + k * h_mode, stop)
            if end - t_c <= tol:
                continue  # already at the end of this step (it ran ahead)
            steppers[ci](t_c, end - t_c)
            tc[ci] = end
            changed[ci] = True
        setters, getters, prod = table.setters, table.getters, self.prod
        for ci in mode.refresh:
            if changed[ci] or any(changed[cp] for cp in prod[ci]):
                setters[ci]()
                getters[ci]()
                changed[ci] = True
        self.t = table.t = t1
        self.mode_time[mode.name] += h
        self.mode_steps[mode.name] += 1
        for j, sig in enumerate(self.events):
            if changed[sig.ci]:
                self.ev_values[j] = sig.read()
        for ci in self.cond_comps:
            if changed[ci]:
                nxt = self._pick(changed)
                break
        else:
            nxt = mode
        info.steps += 1
        self._next(info, mode, nxt, changed, t1)

    def _next(self, info, mode, nxt, changed, t1):
        """After a step of `mode` to t1: the mode `nxt` the next step takes, in `info` too."""
        if nxt is not mode:
            active_now = set(nxt.order)
            for ci in range(self.n):
                if ci not in active_now:
                    self.suspended[ci] = True
        self.next_mode = nxt
        info.t = t1
        info.changed = changed
        if nxt is not mode:
            info.mode_changed = True
            info.mode = nxt.name
        else:
            info.mode_changed = False
        info.record_every = mode.record_every
        info.last = t1 >= self.plan.stop

    def refresh_for_record(self):
        # every active component's inputs and feedthrough outputs as they stand now (the step
        # loop refreshes only what the next steps need); rows are also recorded at each mode
        # change, so a component suspended by the change holds its outputs at that time
        setters, getters, has_ft = self.table.setters, self.table.getters, self.table.has_ft
        for ci in self.active_order:
            setters[ci]()
            if has_ft[ci]:
                getters[ci]()

    def finish(self, info):
        self.mode = self.next_mode
        for ci in self.mode.order:
            self.table.setters[ci]()

    def statistics(self):
        return {m: {"steps": self.mode_steps[m], "simulated_time": self.mode_time[m]} for m in self.mode_steps}
