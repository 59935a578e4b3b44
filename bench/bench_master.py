"""Benchmark the master on the detumble system and time the slew case 3 chain.

    python bench/bench_master.py [--steps 4000] [--repeat 3]

Prints, for build/ssp/detumble.ssp (Gauss-Seidel, 15 ms, stop condition off so every run
takes the same number of steps):
- communication steps per second, recording every connector and recording nothing extra;
- the floor: the time spent inside the FMUs' own fmi2Set*/fmi2DoStep/fmi2Get* calls through
  FMPy's ctypes functions, measured in the same run by timing each call;
- the master's overhead per step in that same run: its wall time less the time inside the
  FMU calls and less the timing wrappers' own cost;
- the wall time of thesis slew case 3 (three chained 180 deg slews, 11 084 steps).
Build first: python build_fmus.py
"""
import argparse
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import system_ssp  # noqa: E402
from system_ssp.neighbor import thesis  # noqa: E402
from system_ssp.master import instances  # noqa: E402

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


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--steps", type=int, default=4000)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    n = args.steps
    print(f"detumble system, Gauss-Seidel, h = 15 ms, {n} steps per run, best of {args.repeat}")
    with system_ssp.System(SSP / "detumble.ssp") as system:
        few = ["dynamics.q_BN[4]"]
        for label, outputs in (("all connectors recorded", None), ("one signal recorded", few)):
            walls = []
            for _ in range(args.repeat):
                t0 = time.perf_counter()
                run_detumble(system, n, outputs)
                walls.append(time.perf_counter() - t0)
            best = min(walls)
            print(f"  {label:<26} {n / best:9.0f} steps/s   {best / n * 1e6:7.1f} us/step "
                  f"(median {statistics.median(walls) / n * 1e6:.1f})")
        untimed_one = best / n

        wrapper_cost, inside_cost = clock_cost()
        timer = CallTimer()
        uninstall = timer.install()
        try:
            t0 = time.perf_counter()
            run_detumble(system, n, few)
            timed_wall = time.perf_counter() - t0
        finally:
            uninstall()
        calls_per_step = timer.calls / n
        # time inside the FMU calls, less what the timing itself adds inside the measured span
        floor = (timer.total - timer.calls * inside_cost) / n
        # the rest of the same run, less the wrappers' own cost, is the master's
        overhead = (timed_wall - timer.total - timer.calls * (wrapper_cost - inside_cost)) / n
        print(f"  FMU calls per step        {calls_per_step:9.1f}")
        print(f"  floor (inside FMU calls)  {floor * 1e6:9.1f} us/step  "
              f"({floor / calls_per_step * 1e6:.2f} us per call)")
        print(f"  master overhead           {overhead * 1e6:9.1f} us/step over the floor, same run "
              f"(timing wrappers' {wrapper_cost * 1e9:.0f} ns/call taken out)")
        print(f"  untimed one-signal run    {untimed_one * 1e6:9.1f} us/step")

    t0 = time.perf_counter()
    results = thesis.run_cases(SSP, "euler", cases=["slew_case3"])
    wall = time.perf_counter() - t0
    s3 = results["slew_case3"]
    print(f"slew case 3 (after detumble case 1): {s3.steps} steps, {s3.duration:.3f} s simulated, "
          f"{s3.propellant:.3f} g; wall {s3.wall_time:.2f} s in the master's runs "
          f"({wall:.2f} s including loading both systems and the 664-step detumble run)")


if __name__ == "__main__":
    main()
