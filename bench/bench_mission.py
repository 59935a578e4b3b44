"""Benchmark the full NEIGHBOR mission run.

    python bench/bench_mission.py [--orbit averaged|cowell] [--scenario 420km] [--profile] [--compare]

One run of the mission system from deployment to re-entry: 5 years idle, 30 days of grace, the
final contact, the de-orbit (10 min attitude determination, detumble, slew and the burn at
15 ms attitude steps), monitoring until the battery is empty, then decay to re-entry. Prints the
wall time (the master's compiled step loop, system_ssp.master.compiled) and the steps and
simulated time per schedule mode. With --profile a second run times each component (set inputs
+ doStep + get outputs) and the master itself; the profiler runs the Python step loop, so that
run is slower. With --compare the same mission runs again in second processes with the Python
step loop (NEIGHBOR_COSIM_COMPILED_LOOP=0) and with the standard FMI calls only
(NEIGHBOR_COSIM_BATCHED_STEPS=0: no batched step, Python loop), and the ratios are printed; the
results must be the same (every value of the mission summary, bit for bit). The first run in a
process includes numba compiling the orbit and atmosphere kernels (about 5-10 s; cached after
the first process). Issue 27's target: 20 s.
Build first: python build_fmus.py
"""
import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from system_ssp.master.observers import profile_table  # noqa: E402
from system_ssp.neighbor import mission  # noqa: E402

BASELINES = (("the Python step loop", {"NEIGHBOR_COSIM_COMPILED_LOOP": "0"}),
             ("the standard FMI calls only", {"NEIGHBOR_COSIM_BATCHED_STEPS": "0"}))


def _plain(summary):
    """The summary as JSON gives it back (every number to its last bit: floats print exactly),
    without the run's wall time."""
    return json.loads(json.dumps({k: v for k, v in summary.items() if k != "wall_time_s"}, default=str))


def _timed(args, profile=False):
    t0 = time.perf_counter()
    s, r = mission.run_mission(args.scenario, args.orbit, profile=profile)
    return time.perf_counter() - t0, s, r


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--orbit", choices=list(mission.SYSTEMS), default="averaged")
    ap.add_argument("--scenario", choices=mission.SCENARIOS, default="420km")
    ap.add_argument("--profile", action="store_true", help="also a run with the time per component")
    ap.add_argument("--compare", action="store_true", help="also run the Python loop and the standard calls, "
                    "print the ratios")
    ap.add_argument("--json", action="store_true", help=argparse.SUPPRESS)  # the --compare runs' answer
    args = ap.parse_args()
    wall, s, r = _timed(args)
    if args.json:
        print(json.dumps({"wall": wall, "steps": r.steps, "summary": _plain(s)}))
        return
    print(f"mission {args.scenario}, {args.orbit} orbit: {wall:.1f} s wall (run {r.wall_time:.1f} s), "
          f"{r.steps} steps, {s['simulated_years']:.2f} simulated years; {r.stop_reason}")
    print(f"{'mode':<16}{'steps':>9}{'simulated':>16}")
    for name, m in r.modes.items():
        print(f"{name:<16}{m['steps']:9d}{m['simulated_time']:14.0f} s")
    if args.profile:
        pwall, _, pr = _timed(args, profile=True)
        prof = pr.profile
        print(f"profiled run (Python step loop, the standard FMI calls): {pwall:.1f} s wall")
        print(profile_table(prof))
    if args.compare:
        for what, env in BASELINES:
            proc = subprocess.run([sys.executable, __file__, "--orbit", args.orbit, "--scenario", args.scenario,
                                   "--json"], env=dict(os.environ, **env), capture_output=True, text=True, check=True)
            base = json.loads(proc.stdout.strip().splitlines()[-1])
            differ = sorted(k for k, v in _plain(s).items() if base["summary"].get(k) != v)
            same = base["steps"] == r.steps and not differ
            verdict = "the same results" if same else "RESULTS DIFFER: " + ", ".join(differ)
            print(f"{what} (second process): {base['wall']:.1f} s wall; the compiled loop "
                  f"{base['wall'] / wall:.2f}x faster ({verdict})")


if __name__ == "__main__":
    main()
