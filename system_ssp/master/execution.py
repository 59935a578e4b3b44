"""One run of a loaded system: instances, initialization, the algorithm's loop under its
observers, the result; the instances are freed whatever happens."""
from .algorithms import FixedStepAlgorithm, ScheduledAlgorithm
from .instances import InstanceTable, StepFailed
from .observers import Observer, ProgressBar, Profiler, Recorder, StepInfo, StopConditions
from .result import Result


def execute(system, plan, progress=False):
    """Run `plan` on `system` with fresh FMU instances; returns a Result (wall_time 0: the
    caller measures it)."""
    table = InstanceTable(system, plan)
    try:
        table.instantiate()
        table.prepare()
        table.initialize()
        algorithm = (ScheduledAlgorithm if plan.schedule is not None else FixedStepAlgorithm)(table, plan)
        expected = plan.n_steps // plan.record_every + 2 if plan.schedule is None else 1024
        recorder = Recorder(table, plan.record, algorithm.refresh_for_record, capacity=min(expected, 1 << 16))
        observers = [recorder]
        if plan.stops:  # first: the recorder records a row where a stop condition fires
            observers.insert(0, StopConditions(table, plan.stops))
        bar = ProgressBar(plan) if progress else None
        if bar is not None:
            observers.append(bar)
        profiler = None
        if plan.profile and plan.schedule is not None:
            profiler = Profiler(algorithm, [c.name for c in system.comps])
            observers.append(profiler)
        info = StepInfo(plan.start, plan.record_every)
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
        reason = f"stop condition {info.fired} at t={info.t:g} s" if info.fired is not None else "reached stop time"
        return Result(data=recorder.data(), stop_time=info.t, stop_reason=reason, steps=info.steps,
                      final=table.final(), wall_time=0.0, start_time=plan.start,
                      step_size=None if plan.schedule is not None else plan.step_size, algorithm=plan.algorithm,
                      order=[system.comps[i].name for i in plan.order], messages=table.messages(),
                      modes=algorithm.statistics(), profile=profiler.report() if profiler else None)
    except StepFailed as f:
        raise table.error(f.ci, f.call, status=f.status) from None
    finally:
        table.free()
