"""One run of a loaded system: instances, initialization, the algorithm's loop under its
observers, the result; the instances are freed whatever happens. A run that fails or is
interrupted raises with the rows recorded so far (`err.result`)."""
import signal
from typing import List, Optional, Sequence

from ..errors import RealTimeOverrun, RunInterrupted, RunTimedOut, SimulationError
from .algorithms import Algorithm, FixedStepAlgorithm, ScheduledAlgorithm
from .instances import InstanceTable, StepFailed
from .interrupts import Interrupted, Interruption, SignalWatch, TimedOut, WallClockLimit
from .observers import Observer, ProgressBar, Profiler, Recorder, RunView, StepInfo, StopConditions
from .events import ScenarioEvents
from .pacing import RealTimePacer
from .result import REACHED_STOP_TIME, Result

DISCARD = 2  # fmi2Discard: a co-simulation FMU that could not complete the step (or ended the simulation)


def execute(system, plan, progress=False, timeout=None, observers=(), real_time=None, stop_on_overrun=False):
    """Run `plan` on `system` with fresh FMU instances; returns a Result (wall_time 0: the
    caller measures it). `timeout`: seconds of wall time from the first step, or None;
    `observers`: the caller's, after the master's own; `real_time`: pace the communication
    points to wall time at this factor (see pacing), `stop_on_overrun`: stop at the first overrun."""
    table = InstanceTable(system, plan)
    run = _Run(system, plan, table)
    with SignalWatch() as watch:
        try:
            table.instantiate()
            table.prepare()
            table.initialize()
            return run.loop(progress, watch, timeout, observers, real_time, stop_on_overrun)
        except StepFailed as f:
            ended = table.terminated_at(f.ci) if (f.call, f.status) == ("fmi2DoStep", DISCARD) else None
            if ended is not None:
                return run.ended_by(f.ci, ended)
            err = table.error(f.ci, f.call, status=f.status, names=f.names)
            err.result = run.partial(f"failed at t={table.t:g} s")
            raise err from None
        except SimulationError as err:
            err.result = run.partial(f"failed at t={table.t:g} s")
            raise
        except RealTimeOverrun as err:
            run.record_last()
            err.result = run.partial(f"real-time overrun at t={run.info.t:g} s")
            raise
        except TimedOut:
            run.record_last()
            timed_out = RunTimedOut(f"wall-clock limit of {timeout:g} s reached at t = {run.info.t:g} s")
            timed_out.result = run.partial(f"timed out at t={run.info.t:g} s")
            raise timed_out from None
        except Interrupted as stop:
            name = signal.Signals(stop.signum).name
            run.record_last()
            interrupted = RunInterrupted(f"interrupted ({name}) at t = {run.info.t:g} s", stop.signum)
            interrupted.result = run.partial(f"interrupted ({name}) at t={run.info.t:g} s")
            raise interrupted from None
        finally:
            table.free()


class _Run:
    """The observers and step info of one run, kept so that a failure can report what the run
    had recorded."""

    def __init__(self, system, plan, table):
        self.system, self.plan, self.table = system, plan, table
        self.recorder = self.info = self.algorithm = self.events = None

    def loop(self, progress: bool, watch: SignalWatch, timeout: Optional[float] = None,
             callers: Sequence[Observer] = (), real_time: Optional[float] = None,
             stop_on_overrun: bool = False) -> Result:
        system, plan, table = self.system, self.plan, self.table
        # before the algorithm, which takes the table's steppers: the events wrap those they fault
        events = ScenarioEvents(table, plan.events) if plan.events else None
        self.events = events
        algorithm: Algorithm = (ScheduledAlgorithm if plan.schedule is not None else FixedStepAlgorithm)(table, plan)
        expected = plan.n_steps // plan.record_every + 2 if plan.schedule is None else 1024
        recorder = Recorder(table, plan.record, algorithm.refresh_for_record, capacity=min(expected, 1 << 16))
        observers: List[Observer] = [recorder]
        stops = StopConditions(table, plan.stops) if plan.stops else None
        if stops is not None:  # first: the recorder records a row where a stop condition fires
            observers.insert(0, stops)
        if events is not None:  # before the stop conditions: what an event sets is seen at its point
            observers.insert(0, events)
        bar = ProgressBar(plan) if progress else None
        if bar is not None:
            observers.append(bar)
        profiler = None
        if plan.profile:
            profiler = Profiler(algorithm, table, [c.name for c in system.comps])
            observers.append(profiler)
        view = RunView(table, algorithm.refresh_for_record)
        for obs in callers:
            obs.attach(view)
            observers.append(obs)
        # the profiler and a caller's step() watch every step: the Python loop. Before the
        # wall-clock limit starts: the compiled loop loads its code here (about a second in a
        # new process), which is not the run's time
        pacer = RealTimePacer(real_time, stop_on_overrun, watch) if real_time is not None else None
        # pacing sleeps between the points: the Python loop (the compiled one runs many steps a call)
        python_loop = profiler is not None or pacer is not None or events is not None
        if not python_loop and all(type(obs).step is Observer.step for obs in callers):
            algorithm.compile(stops.ops if stops is not None else [], recorder)
        if timeout is not None:
            observers.append(WallClockLimit(timeout))
        if pacer is not None:  # after the recorder: a row is taken when the point is reached, not after the wait
            observers.append(pacer)
        observers.append(Interruption(watch))  # last: the row of this step is recorded first
        info = StepInfo(plan.start, plan.record_every)
        self.recorder, self.info, self.algorithm = recorder, info, algorithm
        algorithm.start(info)
        try:
            for obs in observers:
                obs.start(info)
            algorithm.run(info, [obs.step for obs in observers if type(obs).step is not Observer.step])
            for obs in observers:
                obs.finish(info)
        finally:
            if bar is not None:
                bar.close()  # also when a step failed
        algorithm.finish(info)
        reason = f"stop condition {info.fired} at t={info.t:g} s" if info.fired is not None else REACHED_STOP_TIME
        return self.result(recorder.data(), info.t, reason, final=table.final(), modes=algorithm.statistics(),
                           profile=profiler.report() if profiler else None,
                           pacing=pacer.report() if pacer else None)

    def event_log(self):
        return list(self.events.log) if self.events is not None else []

    def ended_by(self, ci, t_end):
        """The run as a component ended it (fmi2Discard, then fmi2Terminated): a last row at the
        time it reached, with its outputs read there (FMI 2.0 allows fmi2Get* after the discard);
        the other components' values are those of the last communication point."""
        table, info = self.table, self.info
        table.get(ci)
        table.t = info.t = t_end
        self.recorder.record(t_end)
        reason = (f"component {self.system.comps[ci].name!r} ended the simulation at t={t_end:g} s "
                  "(fmi2Discard, fmi2Terminated)")
        return self.result(self.recorder.data(), t_end, reason, final=table.final(),
                           modes=self.algorithm.statistics(), profile=None)

    def record_last(self):
        """Record the communication point reached (the FMUs are healthy: an interruption)."""
        r, info = self.recorder, self.info
        if r is not None and r.count and r.times[r.count - 1] != info.t:
            r.record(info.t)

    def partial(self, reason):
        """A Result with the rows recorded so far, or None before the first row."""
        r = self.recorder
        if r is None or r.count == 0:
            return None
        data = r.data()
        return self.result(data, float(data["time"][-1]), reason, final={}, partial=True)

    def result(self, data, stop_time, reason, final, **extra):
        """A Result of this run (wall_time 0: the caller measures it)."""
        plan = self.plan
        return Result(data=data, stop_time=stop_time, stop_reason=reason, steps=self.info.steps, final=final,
                      wall_time=0.0, start_time=plan.start,
                      step_size=None if plan.schedule is not None else plan.step_size, algorithm=plan.algorithm,
                      order=[self.system.comps[i].name for i in plan.order], messages=self.table.messages(),
                      units=self.units(), step_size_source=None if plan.schedule is not None
                      else plan.step_size_source,
                      stop_conditions=[f"{self.system.comps[ci].name}.{var}" for ci, var in plan.stops],
                      events=self.event_log(), **extra)

    def units(self):
        comps = self.system.comps
        units = {"time": "s"}
        for ci, var in self.plan.record:
            units[f"{comps[ci].name}.{var}"] = self.system.var_unit(comps[ci], var)
        return units
