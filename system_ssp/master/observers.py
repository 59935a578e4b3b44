"""What watches a run: recording, stop conditions, the progress bar and profiling.

The execution calls every observer after initialization (`start`), once per macro step after the
algorithm has stepped the components (`step`, in list order: stop conditions first, so that the
recorder knows whether the run stops here), and at the end (`finish`). They share one `StepInfo`
that the algorithm fills in."""
import sys
import threading
import time
from typing import Dict, Sequence, Union

import numpy as np

from .instances import read_ops
from .names import split_name
from .plotting import TIME_UNITS

# The progress bar's display units (the master knows nothing of the models, so not from components).
DAY = 86400.0  # s
YEAR = 365.25 * DAY  # s, Julian year

RESULT_DTYPE = {"Real": np.float64, "Integer": np.int64, "Boolean": np.bool_, "String": object}


class StepInfo:
    """The state of the run after a macro step, written by the algorithm and the observers."""
    __slots__ = ("t", "steps", "changed", "mode_changed", "record_every", "last", "fired", "mode")

    def __init__(self, t, record_every):
        self.t = t  # time reached
        self.steps = 0  # macro steps taken
        self.changed = None  # per component: stepped or refreshed in this step (None: all)
        self.mode_changed = False  # the schedule picks another mode for the next step
        self.record_every = record_every  # the current recording interval, in macro steps
        self.last = False  # the stop time is reached
        self.fired = None  # name of the stop signal that is true, once one is
        self.mode = None  # scheduled runs: the nc:Mode the next step is taken in


class RunView:
    """What an observer may read of the run it watches: the current values of variables, by
    'component.variable' name (inputs and outputs brought up to date as for a recorded row)."""

    def __init__(self, table, refresh):
        self._table, self._refresh = table, refresh
        self._ops = {}

    def read(self, names: Sequence[str]) -> Dict[str, Union[float, int, bool]]:
        """{name: current value} of the named Real, Integer or Boolean variables; SSPError names
        an unknown one."""
        key = tuple(names)
        ops = self._ops.get(key)
        if ops is None:
            comps = self._table.system.comps
            wanted = []
            for name in key:
                comp, var = split_name(comps, name, "observed variable")
                wanted.append((comp.index, var))
            ops = self._ops[key] = read_ops(self._table, wanted)[0]
        self._refresh()
        out: Dict[str, Union[float, int, bool]] = {}
        for op in ops:
            boolean = op.call == "fmi2GetBoolean"
            for name, value in zip(op.names, op.read().tolist()):
                out[name] = bool(value) if boolean else value
        return out


class Observer:
    """Watches a run: `attach` once before the run (a `RunView` to read values through), `start`
    after initialization, `step` after every macro step (`info.t`, `info.steps`; set
    `info.fired` to a text to stop the run there) and `finish` at the end. Pass instances as
    `System.run(..., observers=[...])`; override only what you need."""

    def attach(self, run: RunView) -> None:
        pass

    def start(self, info: StepInfo) -> None:
        pass

    def step(self, info: StepInfo) -> None:
        pass

    def finish(self, info: StepInfo) -> None:
        pass


class StopConditions(Observer):
    """Stops the run at the first communication point where a stop signal (Boolean output) is
    true; re-reads the signals only of components that changed in the step."""

    def __init__(self, table, stops):
        self.ops, _ = read_ops(table, stops)
        self.comps = [op.ci for op in self.ops]

    def check(self):
        """Name of the first stop signal that is true, or None."""
        for op in self.ops:
            view = op.read()
            for j in range(op.n):
                if view[j]:
                    return op.names[j]
        return None

    def start(self, info):
        if self.ops:
            info.fired = self.check()

    def step(self, info):
        if self.ops and (info.changed is None or any(info.changed[ci] for ci in self.comps)):
            info.fired = self.check()


class Recorder(Observer):
    """Rows of the recorded variables: at the start, every `record_every` macro steps, whenever
    the schedule changes mode, when a stop condition fires and at the end."""

    def __init__(self, table, record, refresh, capacity=1024):
        self.record_names = [f"{table.system.comps[ci].name}.{var}" for ci, var in record]
        ops, columns = read_ops(table, record)
        self.columns = dict(columns)
        # numbers go into a float matrix, texts (String variables) into a list per row
        self.ops = [op for op in ops if op.view is not None]
        self.text_ops = [op for op in ops if op.view is None]
        numbers = [c for c in columns if c[1] != "String"]
        self.col_of = {name: j for j, (name, _) in enumerate(numbers)}
        self.text_col_of = {name: j for j, (name, _) in enumerate(c for c in columns if c[1] == "String")}
        self.texts = []
        self.refresh = refresh  # brings the values to record up to date (the algorithm's)
        self.rows = np.zeros((max(capacity, 2), len(numbers)))
        self.times = np.zeros(len(self.rows))
        self.count = 0
        self.since = 0

    def record(self, t):
        if self.count == len(self.rows):
            self.rows = np.concatenate([self.rows, np.zeros_like(self.rows)])
            self.times = np.concatenate([self.times, np.zeros_like(self.times)])
        self.refresh()
        r = self.rows[self.count]
        col = 0
        for op in self.ops:
            r[col:col + op.n] = op.read()
            col += op.n
        if self.text_ops:
            self.texts.append([text for op in self.text_ops for text in op.read()])
        self.times[self.count] = t
        self.count += 1
        self.since = 0

    def start(self, info):
        self.record(info.t)

    def step(self, info):
        self.since += 1
        if self.since >= info.record_every or info.mode_changed or info.fired is not None or info.last:
            self.record(info.t)

    def finish(self, info):
        if self.times[self.count - 1] != info.t:
            self.record(info.t)

    def data(self):
        """The rows as a numpy structured array: 'time', then the recorded variables in the
        order asked for."""
        n = self.count
        dtype = [("time", np.float64)] + [(name, RESULT_DTYPE[self.columns[name]]) for name in self.record_names]
        data = np.zeros(n, dtype=dtype)
        data["time"] = self.times[:n]
        for name in self.record_names:
            if name in self.text_col_of:
                j = self.text_col_of[name]
                data[name] = [row[j] for row in self.texts[:n]]
                continue
            col = self.rows[:n, self.col_of[name]]
            data[name] = col.astype(RESULT_DTYPE[self.columns[name]]) if self.columns[name] != "Boolean" else col != 0
        return data


class ProgressBar(Observer):
    """tqdm on stderr in simulated time, in the unit the span reads best in (s, days or years):
    of the stop time for runs that end there; without a total (no percentage, no ETA to a time
    the run may never reach) when a stop condition may end the run first. The ETA is the average
    rate since the start (smoothing 0: stable for runs whose speed changes with the mode), and
    the bar shows only once a run has lasted a second. A scheduled run shows its mode, the time
    spent in it (in the unit that reads best) and the steps per second. The bar is redrawn at
    least twice a second whatever the steps' size: tqdm's adaptive `miniters` would wait for an
    advance as large as the coasts' during a 15 ms phase, and the bar would look hung."""

    UNITS = ((2 * YEAR, "yr", YEAR), (2 * DAY, "d", DAY), (0.0, "s", 1.0))

    def __init__(self, plan):
        self.plan = plan
        self.bar = None
        span = plan.stop - plan.start
        _, self.unit, self.scale = next(u for u in self.UNITS if span >= u[0])
        self.chunk = 1 if plan.schedule is not None else max(1, plan.n_steps // 500)
        self.mode, self.mode_t0 = None, plan.start
        self.posted, self.posted_steps = 0.0, 0
        self.drawn_steps = 0  # steps at the last update (the compiled loop reports several steps at once)

    def start(self, info):
        try:
            from tqdm import tqdm  # optional: no bar without it
        except ImportError:
            return
        p = self.plan
        total = None if p.stops else (p.stop - p.start) / self.scale
        self.bar = tqdm(total=total, file=sys.stderr, unit=self.unit, leave=False, mininterval=0.5, miniters=0,
                        delay=1.0, smoothing=0.0, dynamic_ncols=True, bar_format=None if total else
                        "{desc}{n:.4g} {unit} simulated [{elapsed}, {rate_fmt}{postfix}]")
        self.mode, self.mode_t0 = info.mode, info.t
        self.posted, self.posted_steps = time.perf_counter(), info.steps
        # a step can take seconds (an FMU compiling its kernels, a long Cowell step): redraw the
        # bar every second from a thread so that its clock never stops
        self.stopped = threading.Event()
        self.ticker = threading.Thread(target=self._tick, name="progress-bar", daemon=True)
        self.ticker.start()

    def _tick(self):
        while not self.stopped.wait(1.0):
            bar = self.bar
            if bar is not None and time.time() - bar.start_t >= bar.delay:
                bar.refresh()

    def step(self, info):
        bar = self.bar
        if bar is None or info.steps - self.drawn_steps < self.chunk:
            return
        self.drawn_steps = info.steps
        if info.mode != self.mode:  # the scheduled algorithm names the next step's mode
            self.mode, self.mode_t0 = info.mode, info.t
        now = time.perf_counter()
        if now - self.posted >= 0.5:
            rate = (info.steps - self.posted_steps) / (now - self.posted)
            where = f"{self.mode} for {self._span(info.t - self.mode_t0)}, " if self.mode else ""
            bar.set_postfix_str(f"{where}{rate:,.0f} steps/s", refresh=False)
            self.posted, self.posted_steps = now, info.steps
        bar.update((info.t - self.plan.start) / self.scale - bar.n)

    @staticmethod
    def _span(seconds):
        unit, size = next((u, s) for u, s in TIME_UNITS if seconds >= 2 * s or u == "s")
        return f"{seconds / size:.3g} {unit}"

    def close(self):
        if self.bar is not None:
            self.stopped.set()
            self.ticker.join()
            self.bar.close()
            self.bar = None

    def finish(self, info):
        self.close()


class Profiler(Observer):
    """Wall time per component in its calls (inputs set, doStep, outputs read: every call of the
    run's algorithm, Jacobi, Gauss-Seidel and scheduled alike) and of the loop; the master's share
    is the rest. The component's step runs as its standard FMI calls (the batched step, one call
    for all three, would leave them inseparable), which give the same values."""

    CALLS = ("set", "doStep", "get")

    def __init__(self, algorithm, table, names):
        self.names = names
        self.spent = [[0.0, 0.0, 0.0] for _ in names]  # per component: set, doStep, get
        perf = time.perf_counter

        def timed(ci, which, call):
            cell = self.spent[ci]

            def call_timed(*args):
                w0 = perf()
                call(*args)
                cell[which] += perf() - w0
            return call_timed

        n = len(names)
        # in place: the algorithms hold these lists
        table.setters[:] = [timed(ci, 0, table.setters[ci]) for ci in range(n)]
        table.do_steps[:] = [timed(ci, 1, table.do_steps[ci]) for ci in range(n)]
        table.getters[:] = [timed(ci, 2, table.getters[ci]) for ci in range(n)]

        def standard(set_, do_step, get):
            def step(t, dt):
                set_()
                do_step(t, dt)
                get()
            return step

        algorithm.steppers = [standard(table.setters[ci], table.do_steps[ci], table.getters[ci]) for ci in range(n)]
        self.wall0 = 0.0
        self.total = 0.0

    def start(self, info):
        self.wall0 = time.perf_counter()

    def finish(self, info):
        self.total = time.perf_counter() - self.wall0

    def report(self):
        """{"components": {name: seconds in its calls}, "calls": {name: {"set", "doStep", "get":
        seconds}}, "loop": seconds of the step loop, "master": the loop's rest}."""
        return {"components": {name: sum(cell) for name, cell in zip(self.names, self.spent)},
                "calls": {name: dict(zip(self.CALLS, cell)) for name, cell in zip(self.names, self.spent)},
                "loop": self.total, "master": self.total - sum(sum(cell) for cell in self.spent)}


def profile_table(profile):
    """A run's profile (Profiler.report) as printed: a row per component (its set, doStep and get
    calls and their sum), the slowest first, then the master's own share."""
    lines = [f"wall time in the components' FMI calls, of {profile['loop']:.3f} s in the step loop (s):",
             f"  {'component':<20} {'set':>9} {'doStep':>9} {'get':>9} {'total':>9}"]
    for name, total in sorted(profile["components"].items(), key=lambda kv: -kv[1]):
        c = profile["calls"][name]
        lines.append(f"  {name:<20} {c['set']:9.3f} {c['doStep']:9.3f} {c['get']:9.3f} {total:9.3f}")
    lines.append(f"  {'(master)':<20} {'':>29} {profile['master']:9.3f}")
    return "\n".join(lines)

