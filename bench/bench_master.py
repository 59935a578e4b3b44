"""Benchmark the master on the detumble system and time the slew case 3 chain.

    python bench/bench_master.py [--steps 4000] [--repeat 3]

Prints, for build/ssp/detumble.ssp (Gauss-Seidel, 15 ms, stop condition off so every run
takes the same number of steps), each row measured in this run:
- communication steps per second, recording every connector and recording one signal, with our
  runtime's batched step (neighborStepIO: set, doStep and get in one call into the FMU) and with
  the standard FMI calls only, and their ratio;
- the same (one signal) with the models' Python steps instead of their native ones
  (NEIGHBOR_COSIM_NATIVE=0, in a second process), and the ratio;
- the same with Jacobi (one signal recorded), in the compiled loop and in the Python loop, as a
  ratio of Gauss-Seidel's time;
- the floor: the same three models' wrapper objects (the classes inside the FMUs, with the same
  parameters) called directly in a plain Python loop, no FMI and no master: do_step, with the
  values moved between the arrays the models share with the runtime by numpy indexing (the
  models' own work); the master + FMI cost per FMU call over it; and the same objects called
  through their Python set_real/do_step/get_real by value reference;
- the time inside the FMUs' own fmi2Set*/fmi2DoStep/fmi2Get* calls with the standard calls (each
  call timed), and the master's own overhead per step in that run;
- libcosim (libcosimpy, its fixed-step algorithm, nothing observed) on the same .ssp in a
  second process, and our steps/s over its;
- the wall time of thesis slew case 3 (three chained 180 deg slews, 11 084 steps).
Build first: python build_fmus.py
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import numpy as np  # noqa: E402

import system_ssp  # noqa: E402
from system_ssp.neighbor import thesis  # noqa: E402
from system_ssp import builder  # noqa: E402
from system_ssp.master import compiled, instances  # noqa: E402

SSP = ROOT / "build" / "ssp"


class CallTimer:
    """Wraps every FMU call the master prepared so the time inside them adds up."""

    def __init__(self):
        self.total = 0.0
        self.calls = 0

    def wrap(self, fn):
        clock = time.perf_counter

        def timed(*args):
            t0 = clock()
            status = fn(*args)
            self.total += clock() - t0
            self.calls += 1
            return status

        return timed

    def install(self):
        """Wrap every instance's FMI functions (the ones the master's prepared operations call)
        as soon as the instances exist; returns a function that undoes it."""
        original = instances.InstanceTable.instantiate
        w = self.wrap

        def instantiate(table):
            original(table)
            for inst in table.instances:
                inst.fn = {name: w(fn) for name, fn in inst.fn.items()}

        instances.InstanceTable.instantiate = instantiate

        def uninstall():
            instances.InstanceTable.instantiate = original

        return uninstall


def clock_cost():
    """Cost of the two perf_counter calls and the wrapper around one call, to subtract."""
    timer = CallTimer()
    f = timer.wrap(lambda *a: 0)
    n = 200000
    t0 = time.perf_counter()
    for _ in range(n):
        f(1, 2, 3, 4)
    return (time.perf_counter() - t0) / n, timer.total / n


def run_detumble(system, steps, outputs=None):
    r = system.run(stop_time=steps * 0.015, stop_when=[], outputs=outputs)
    assert r.steps == steps, r.stop_reason
    return r


def _wrapper_class(model_identifier):
    """The NeighborSlave class an FMU of ours carries (fmus/neighbor_<snake name>.py)."""
    snake = re.sub(r"(?<!^)(?=[A-Z])", "_", model_identifier).lower()
    return builder._import_wrapper(builder.FMU_SOURCES / f"neighbor_{snake}.py")


def floor_run(system, steps, through_get_set=False):
    """The system's models as their wrapper objects, called directly in a plain Python loop in the
    master's order: each component's connected inputs set from the outputs read last (the same
    Gauss-Seidel), do_step, its connected outputs read. Models that share their values with the
    runtime (NeighborSlave.share_values) get them moved between their arrays by numpy indexing
    (their own work: do_step), unless `through_get_set`: then every model through its Python
    set_real/get_real (what a Python host calling the objects pays). Returns (wall seconds,
    FMU-call equivalents per step, the final values {component.variable: value})."""
    setters = {"Real": "set_real", "Integer": "set_integer", "Enumeration": "set_integer", "Boolean": "set_boolean",
               "String": "set_string"}
    slaves = []
    for comp in system.comps:
        slave = _wrapper_class(comp.md.coSimulation.modelIdentifier)(instance_name=comp.name,
                                                                     resources=str(builder.FMU_SOURCES))
        slave.setup_experiment(0.0, steps * 0.015)
        slave.enter_initialization_mode()
        slaves.append(slave)
    for (ci, var), value in system.collect_parameters().items():
        v = system.comps[ci].vars[var]
        getattr(slaves[ci], setters[v.type])([v.valueReference], [value])
    for slave in slaves:
        slave.exit_initialization_mode()
    n = len(slaves)
    vr = lambda ci, var: system.comps[ci].vars[var].valueReference  # noqa: E731
    outs = [sorted({vr(ci, lk.src_var) for lk in system.links if lk.src == ci}) for ci in range(n)]
    ins = [[(vr(ci, lk.dst_var), lk.src, vr(lk.src, lk.src_var)) for lk in system.links if lk.dst == ci]
           for ci in range(n)]
    assert all(lk.vtype == "Real" for lk in system.links)  # the detumble system's connections
    values = [dict(zip(outs[ci], slaves[ci].get_real(outs[ci]))) for ci in range(n)]
    order = [system.comps.index(system.by_name[name]) for name in system.default_order()]
    calls = sum(1 + bool(ins[ci]) + bool(outs[ci]) for ci in range(n))
    shared = not through_get_set and all(slave.shared is not None for slave in slaves)
    if shared:
        # per component, per source: (its input indices, the source's array, the source's indices)
        moves = [[(np.array([d for d, s, _ in ins[ci] if s == src]), slaves[src].shared,
                   np.array([v for _, s, v in ins[ci] if s == src])) for src in sorted({s for _, s, _ in ins[ci]})]
                 for ci in range(n)]
    t0 = time.perf_counter()
    if shared:
        steps_of = [(slaves[ci].shared, moves[ci], slaves[ci].do_step) for ci in order]
        for k in range(steps):
            t = k * 0.015
            for array, sources, do_step in steps_of:
                for dst, src_array, src in sources:
                    array[dst] = src_array[src]
                do_step(t, 0.015)
    else:
        for k in range(steps):
            t = k * 0.015
            for ci in order:
                slave = slaves[ci]
                if ins[ci]:
                    slave.set_real([d for d, _, _ in ins[ci]], [values[src][s] for _, src, s in ins[ci]])
                slave.do_step(t, 0.015)
                if outs[ci]:
                    values[ci] = dict(zip(outs[ci], slave.get_real(outs[ci])))
    wall = time.perf_counter() - t0
    final = {f"{system.comps[ci].name}.{v.name}": slaves[ci].get_real([v.valueReference])[0]
             for ci in range(n) for v in system.comps[ci].md.modelVariables if v.causality == "output"
             and v.type == "Real"}
    return wall, calls, final


# libcosim's steps of the same system, timed in its own process (a process holding both libcosim
# and FMPy instances can abort at exit)
LIBCOSIM = """
import sys, time
from libcosimpy.CosimExecution import CosimExecution
from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
log_output_level(CosimLogLevel.WARNING)
ex = CosimExecution.from_ssp_file(sys.argv[1], step_size=15_000_000)
ex.step(1)  # initialization happens in the first step
best = None
for _ in range(int(sys.argv[3])):
    t0 = time.perf_counter()
    ex.step(int(sys.argv[2]))
    wall = time.perf_counter() - t0
    best = wall if best is None else min(best, wall)
print(best)
"""


def libcosim_steps_per_second(steps, repeat):
    """libcosim's steps/s on detumble.ssp (best of `repeat`), or None without libcosimpy."""
    proc = subprocess.run([sys.executable, "-c", LIBCOSIM, str(SSP / "detumble.ssp"), str(steps), str(repeat)],
                          capture_output=True, text=True)
    if proc.returncode != 0:
        return None
    return steps / float(proc.stdout.strip().splitlines()[-1])


def best_of(repeat, run):
    walls = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        run()
        walls.append(time.perf_counter() - t0)
    return min(walls), statistics.median(walls)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--steps", type=int, default=4000)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--one-signal", action="store_true", help=argparse.SUPPRESS)  # the second process's answer
    args = ap.parse_args()
    n = args.steps
    if args.one_signal:
        with system_ssp.System(SSP / "detumble.ssp") as system:
            print(n / best_of(args.repeat, lambda: run_detumble(system, n, ["dynamics.q_BN[4]"]))[0])
        return
    print(f"detumble system, Gauss-Seidel, h = 15 ms, {n} steps per run, best of {args.repeat}")
    with system_ssp.System(SSP / "detumble.ssp") as system:
        few = ["dynamics.q_BN[4]"]
        best = {}
        for label, outputs in (("all connectors recorded", None), ("one signal recorded", few)):
            for batched in (True, False):
                instances.BATCHED_STEPS = batched
                best[(label, batched)], _ = best_of(args.repeat, lambda o=outputs: run_detumble(system, n, o))
            instances.BATCHED_STEPS = True
            fast, slow = best[(label, True)], best[(label, False)]
            print(f"  {label:<26} {n / fast:9.0f} steps/s batched, {n / slow:7.0f} standard calls: "
                  f"{slow / fast:.2f}x")
        one = best[("one signal recorded", True)] / n
        # the models' native steps (components.core.native) against their Python steps, same run
        proc = subprocess.run([sys.executable, __file__, "--one-signal", "--steps", str(n), "--repeat",
                               str(args.repeat)], capture_output=True, text=True,
                              env=dict(os.environ, NEIGHBOR_COSIM_NATIVE="0"))
        if proc.returncode == 0:
            python_steps = float(proc.stdout.strip().splitlines()[-1])
            print(f"  {'the same, Python steps':<26} {python_steps:9.0f} steps/s (NEIGHBOR_COSIM_NATIVE=0): the native "
                  f"steps {1 / one / python_steps:.2f}x faster")
        # Jacobi (libcosim's algorithm) on the same system: the compiled loop, and the Python loop it replaced
        for label, on in (("Jacobi, one signal recorded", True), ("Jacobi in the Python loop", False)):
            compiled.ENABLED = on
            best[label], _ = best_of(args.repeat, lambda: system.run(stop_time=n * 0.015, stop_when=[], outputs=few,
                                                                     algorithm="jacobi"))
            compiled.ENABLED = True
            print(f"  {label:<26} {n / best[label]:9.0f} steps/s, {best[label] / (one * n):.2f}x Gauss-Seidel's time "
                  "(one signal)")

        python_get_set = min(floor_run(system, n, through_get_set=True)[0] for _ in range(args.repeat)) / n
        floor_walls = []
        for _ in range(args.repeat):
            wall, calls, final = floor_run(system, n)
            floor_walls.append(wall)
        floor = min(floor_walls) / n
        r = run_detumble(system, n, list(final))
        same = all(r.final[name] == value for name, value in final.items())
        print(f"  floor: the models called directly in Python {n * 1.0 / (floor * n):9.0f} steps/s, "
              f"{floor * 1e6:.1f} us/step ({'the same final state' if same else 'final state DIFFERS'} as the master; "
              "values moved between the models' shared arrays)")
        print(f"  the same objects through their Python set_real/get_real {1.0 / python_get_set:9.0f} steps/s, "
              f"{python_get_set * 1e6:.1f} us/step")
        print(f"  master + FMI over the floor {(one - floor) * 1e6:9.1f} us/step, "
              f"{(one - floor) / calls * 1e6:.2f} us per FMU call ({calls} set/doStep/get calls a step), "
              f"the master's run at {one / floor:.2f}x the floor")

        instances.BATCHED_STEPS = False
        wrapper_cost, inside_cost = clock_cost()
        timer = CallTimer()
        uninstall = timer.install()
        try:
            t0 = time.perf_counter()
            run_detumble(system, n, few)
            timed_wall = time.perf_counter() - t0
        finally:
            uninstall()
            instances.BATCHED_STEPS = True
        calls_per_step = timer.calls / n
        # time inside the FMU calls, less what the timing itself adds inside the measured span
        inside = (timer.total - timer.calls * inside_cost) / n
        # the rest of the same run, less the wrappers' own cost, is the master's
        overhead = (timed_wall - timer.total - timer.calls * (wrapper_cost - inside_cost)) / n
        print(f"  standard calls, each timed: {calls_per_step:.1f} FMU calls per step, {inside * 1e6:.1f} us/step "
              f"inside them ({inside / calls_per_step * 1e6:.2f} us per call), the master {overhead * 1e6:.1f} us/step "
              "(timing wrappers' cost taken out)")

    ours = n / best[("one signal recorded", True)]
    theirs = libcosim_steps_per_second(n, args.repeat)
    if theirs is None:
        print("  libcosim: not installed (pip install libcosimpy)")
    else:
        print(f"  libcosim, same .ssp, nothing observed {theirs:9.0f} steps/s; ours (one signal) {ours / theirs:.2f}x "
              "faster")

    t0 = time.perf_counter()
    results = thesis.run_cases(SSP, "euler", cases=["slew_case3"])
    wall = time.perf_counter() - t0
    s3 = results["slew_case3"]
    print(f"slew case 3 (after detumble case 1): {s3.steps} steps, {s3.duration:.3f} s simulated, "
          f"{s3.propellant:.3f} g; wall {s3.wall_time:.2f} s in the master's runs "
          f"({wall:.2f} s including loading both systems and the 664-step detumble run)")


if __name__ == "__main__":
    main()
