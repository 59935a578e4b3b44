"""The compiled step loop (issue 27, system_ssp.master.compiled): many macro steps per call from
Python, the FMI functions called through their addresses. It must give the Python loop's results
bit for bit (the same calls with the same values in the same order), in fixed-step and scheduled
runs, with stop conditions, Boolean connections, schedule modes and events; and be used only
where it can serve the run."""
from master_fixtures import helpers as h
from numba.core.dispatcher import Dispatcher
import numpy as np
import pytest

from system_ssp import Observer, SimulationError
from system_ssp.master import algorithms, compiled
from system_ssp.master.system import simulate
from test_master_core import loop_system
from test_master_schedule import scheduled_system

SPAN = compiled.scheduled_span, compiled.fixed_span, compiled.jacobi_span


def _run(path, loop, monkeypatch, **options):
    """simulate(path) with the compiled loop on or off; also how many spans it ran."""
    monkeypatch.setattr(compiled, "ENABLED", loop)
    spans = []

    def counted(function):
        def span(*args):
            spans.append(1)
            return function(*args)
        return span

    monkeypatch.setattr(compiled, "scheduled_span", counted(SPAN[0]))
    monkeypatch.setattr(compiled, "fixed_span", counted(SPAN[1]))
    monkeypatch.setattr(compiled, "jacobi_span", counted(SPAN[2]))
    return simulate(path, **options), len(spans)


def _same(a, b):
    assert list(a.names) == list(b.names)
    assert a.to_pandas().equals(b.to_pandas())  # every recorded value, bit for bit
    assert a.final == b.final and a.stop_reason == b.stop_reason and a.steps == b.steps
    assert a.modes == b.modes  # scheduled: steps and simulated time per mode


# detumble: Real connections and a stop condition (fixed step); attitude_determination: Boolean
# connections and feedthrough sensors; sun_avoidance_slew: the slew guidance chain
@pytest.mark.parametrize("system", ["detumble", "attitude_determination", "sun_avoidance_slew"])
def test_compiled_fixed_step_loop_equals_the_python_loop(ssp_paths, monkeypatch, system):
    python, spans_off = _run(ssp_paths[system], False, monkeypatch)
    fast, spans = _run(ssp_paths[system], True, monkeypatch)
    assert spans_off == 0 and 0 < spans < fast.steps / 5  # many steps per call
    _same(fast, python)


@pytest.mark.parametrize("system, options", [
    ("detumble", {}), ("attitude_determination", {}), ("sun_avoidance_slew", {}),
    ("detumble", {"step_multiples": {"dynamics": 3, "thrusters": 2}, "stop_when": [], "stop_time": 2.0}),
])
def test_compiled_jacobi_loop_equals_the_python_loop(ssp_paths, monkeypatch, system, options):
    """Jacobi (libcosim's algorithm; every run with --algorithm jacobi, every system with OSP's
    annotation) in the compiled loop: every component gathers its inputs from the last
    communication point before any steps, as the Python loop's Jacobi step sets them all first."""
    python, spans_off = _run(ssp_paths[system], False, monkeypatch, algorithm="jacobi", **options)
    fast, spans = _run(ssp_paths[system], True, monkeypatch, algorithm="jacobi", **options)
    assert spans_off == 0 and 0 < spans < fast.steps / 5
    _same(fast, python)
    gauss_seidel, _ = _run(ssp_paths[system], True, monkeypatch, **options)
    assert not gauss_seidel.to_pandas().equals(fast.to_pandas())  # a Jacobi run indeed


def test_compiled_loop_records_every_kth_step_and_at_the_end(ssp_paths, monkeypatch):
    """record_every 7 over a run that ends between rows: the rows on the way come from the
    compiled loop, the last from Python's recorder."""
    options = {"record_every": 7, "stop_time": 2.0, "stop_when": []}
    python, _ = _run(ssp_paths["detumble"], False, monkeypatch, **options)
    fast, _ = _run(ssp_paths["detumble"], True, monkeypatch, **options)
    assert len(fast.data) == len(python.data) > 10
    _same(fast, python)


def test_compiled_scheduled_loop_equals_the_python_loop(ssp_paths, monkeypatch):
    """The de-orbit system's schedule: 0.5 s steps while the propulsion's `burning` signal is
    true (a 39-minute burn, recorded every 60th step), then hour-long coast steps (the mode
    changes where the signal does, mid-span)."""
    options = {"stop_time": 3 * 3600.0, "stop_when": [], "parameters": {"propulsion.burn_enable": True}}
    python, _ = _run(ssp_paths["deorbit"], False, monkeypatch, **options)
    fast, spans = _run(ssp_paths["deorbit"], True, monkeypatch, **options)
    assert 0 < spans < 200 and python.modes["burn"]["steps"] > 4000 and python.modes["coast"]["steps"] > 0
    _same(fast, python)


# integ steps every third 0.1 s step, before gain; gain (y = u, direct feedthrough) steps at every
# step, so the Python loop refreshes it after each (its reader integ steps before it), while the
# compiled loop does so only when integ steps next; rows every fourth step and at the mode change
LAZY = """<nc:Order>integ gain timer</nc:Order><nc:Schedule>
  <nc:Mode name="before" stepSize="0.1" every="integ:3" recordEvery="4">
    <nc:When component="timer" connector="expired" values="0"/></nc:Mode>
  <nc:Mode name="after" stepSize="0.05" every="gain:2"/>
</nc:Schedule>"""


@pytest.fixture(scope="module")
def fmus_for_schedule(tmp_path_factory):
    return h.build_fixture_fmus(tmp_path_factory.mktemp("master_fmus"))


def test_compiled_loop_refreshes_only_what_the_next_step_reads(fmus_for_schedule, tmp_path, monkeypatch):
    """The lazy refresh (compiled.LazyRefresh): refreshes left out, the recorded rows, the final
    values and the mode change the same bit for bit as the Python loop's refresh at every step."""
    ssd = scheduled_system(tmp_path, fmus_for_schedule, schedule=LAZY, expiry=2.05)
    left_out = []
    lazy_refresh = compiled.lazy_refresh

    def kept(*args):
        lazy = lazy_refresh(*args)
        left_out.append(lazy.left_out)
        return lazy

    monkeypatch.setattr(compiled, "lazy_refresh", kept)
    python, _ = _run(ssd, False, monkeypatch, stop_time=3.0)
    fast, spans = _run(ssd, True, monkeypatch, stop_time=3.0)
    assert spans > 0 and python.modes["before"]["steps"] == 21 and python.modes["after"]["steps"] == 18
    assert sum(int(n[0]) for n in left_out) >= 10  # about two of every three steps in "before"
    _same(fast, python)


class _Steps(Observer):
    def __init__(self):
        self.seen = []

    def step(self, info):
        self.seen.append(info.steps)


class _End(Observer):
    def finish(self, info):
        self.t = info.t


def test_python_loop_where_the_compiled_one_cannot_serve(ssp_paths, monkeypatch):
    """The profiler times each component's step and a caller's observer with a step() sees
    every step: the Python loop runs them; one that only watches the end leaves the compiled loop."""
    watcher, end = _Steps(), _End()
    r, spans = _run(ssp_paths["detumble"], True, monkeypatch, stop_time=0.3, observers=[watcher])
    assert spans == 0 and watcher.seen == list(range(1, 21))
    r, spans = _run(ssp_paths["detumble"], True, monkeypatch, stop_time=0.3, observers=[end])
    assert 0 < spans < 20 and end.t == r.stop_time == 0.3
    options = {"stop_time": 600.0, "stop_when": [], "parameters": {"propulsion.burn_enable": True}}
    r, spans = _run(ssp_paths["deorbit"], True, monkeypatch, profile=True, **options)
    assert spans == 0 and r.profile is not None and r.modes["burn"]["steps"] == 1200


@pytest.mark.parametrize("algorithm", ["gauss-seidel", "jacobi"])
def test_the_profiler_times_every_components_calls_in_any_fixed_step_run(ssp_paths, monkeypatch, algorithm):
    """--profile on a system without a schedule (it printed nothing before): the set, doStep and
    get calls of each component timed, in the Python loop with the standard FMI calls, and the
    run's values those of the compiled loop's, bit for bit."""
    fast, _ = _run(ssp_paths["detumble"], True, monkeypatch, algorithm=algorithm)
    profiled, spans = _run(ssp_paths["detumble"], True, monkeypatch, algorithm=algorithm, profile=True)
    assert spans == 0
    _same(fast, profiled)
    prof = profiled.profile
    assert set(prof["components"]) == set(prof["calls"]) == {"detumble", "thrusters", "dynamics"}
    for name, calls in prof["calls"].items():
        assert set(calls) == {"set", "doStep", "get"} and all(v > 0 for v in calls.values())
        assert prof["components"][name] == pytest.approx(sum(calls.values()))
    assert 0 < prof["master"] < prof["loop"]


def test_span_steps_bound_what_one_call_takes(monkeypatch, ssp_paths):
    """Python sees the run at least every SPAN_STEPS steps, and about every SPAN_SECONDS where
    steps are slow (interruptions, the wall-clock limit)."""
    monkeypatch.setattr(algorithms, "SPAN_STEPS", 10)
    r, spans = _run(ssp_paths["detumble"], True, monkeypatch, stop_time=3.0, stop_when=[], record_every=1000)
    assert spans >= 20 and r.steps == 200  # none longer than SPAN_STEPS
    assert np.array_equal(r.data["time"], [0.0, 3.0])
    monkeypatch.setattr(algorithms, "SPAN_STEPS", 2000)
    monkeypatch.setattr(algorithms, "SPAN_SECONDS", 1e-9)  # every span "too long": down to one step each
    r, spans = _run(ssp_paths["detumble"], True, monkeypatch, stop_time=3.0, stop_when=[], record_every=1000)
    assert r.steps == 200 and spans > 150  # 16, 8, 4, 2, then one step per span


def test_a_failure_in_the_compiled_loop_is_the_python_loops(monkeypatch, tmp_path, tmp_path_factory):
    """An FMU raising in its step from t = 0.5 s: the same error, naming the component, and the
    same rows kept up to the last communication point reached, from both loops."""
    ssd = loop_system(tmp_path, h.build_fixture_fmus(tmp_path_factory.mktemp("master_fmus")))
    errors, spans = [], []

    def counted(*args):
        spans.append(1)
        return SPAN[1](*args)

    monkeypatch.setattr(compiled, "fixed_span", counted)
    for on in (False, True):
        monkeypatch.setattr(compiled, "ENABLED", on)
        with pytest.raises(SimulationError, match=r"component 'integ'.*fixture failure at t=0.5 s") as err:
            simulate(ssd, step_size=0.1, stop_time=1.0, outputs=["integ.x"], parameters={"integ.fail_at": 0.5})
        errors.append(err.value)
    python, fast = errors
    assert spans  # the second run's steps and its failure came from the compiled loop
    assert str(fast) == str(python)
    assert fast.result.stop_reason == python.result.stop_reason
    assert fast.result.to_pandas().equals(python.result.to_pandas()) and len(fast.result.data) == 6



def test_the_compiled_loop_counts_no_references():
    """The loop's functions hand the run's tables (about seventy arrays) to one another at every
    component and step; with numba's reference counting every call increfed and decrefed each
    array atomically (9 % of the default mission). Every compiled function of the loop is
    compiled without it (compiled._loop_function; one that allocated would not compile). The
    machine code cannot be inspected here: numba gives no code for functions loaded from its cache."""
    functions = [f for f in vars(compiled).values() if isinstance(f, Dispatcher)]
    assert compiled.scheduled_span in functions and compiled._step in functions and len(functions) >= 15
    assert [f.py_func.__name__ for f in functions if f.targetoptions.get("_nrt", True)] == []
