"""Benchmark the full NEIGHBOR mission run.

    python bench/bench_mission.py [--orbit averaged|cowell] [--scenario 420km]

One run of the mission system from deployment to re-entry: 5 years idle, 30 days of grace, the
final contact, the de-orbit (10 min attitude determination, detumble, slew and the burn at
15 ms attitude steps), monitoring until the battery is empty, then decay to re-entry. Prints the
wall time, the steps and simulated time per schedule mode, and where the time goes: per
component (set inputs + doStep + get outputs) and the master itself. The first run in a process
includes numba compiling the orbit and atmosphere kernels (about 5-10 s). With --compare the same
mission runs again in a second process with the standard FMI calls only
(NEIGHBOR_COSIM_BATCHED_STEPS=0, no batched step) and the ratio of the two is printed; the results
must be the same. Issue 27's target: 20 s. Build first: python build_fmus.py
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

from system_ssp.neighbor import mission  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--orbit", choices=list(mission.SYSTEMS), default="averaged")
    ap.add_argument("--scenario", choices=mission.SCENARIOS, default="420km")
    ap.add_argument("--compare", action="store_true", help="also run with the standard FMI calls only, print the ratio")
    ap.add_argument("--json", action="store_true", help=argparse.SUPPRESS)  # the --compare run's answer
    args = ap.parse_args()
    t0 = time.perf_counter()
    s, r = mission.run_mission(args.scenario, args.orbit, profile=True)
    wall = time.perf_counter() - t0
    if args.json:
        print(json.dumps({"wall": wall, "loop": r.profile["loop"], "steps": r.steps,
                          "total_propellant_kg": s["total_propellant_kg"], "reentry_years": s["simulated_years"]}))
        return
    print(f"mission {args.scenario}, {args.orbit} orbit: {wall:.1f} s wall (run {r.wall_time:.1f} s), "
          f"{r.steps} steps, {s['simulated_years']:.2f} simulated years; {r.stop_reason}")
    print(f"{'mode':<16}{'steps':>9}{'simulated':>16}")
    for name, m in r.modes.items():
        print(f"{name:<16}{m['steps']:9d}{m['simulated_time']:14.0f} s")
    prof = r.profile
    print(f"wall time in the step loop: {prof['loop']:.1f} s")
    for name, sec in sorted(prof["components"].items(), key=lambda kv: -kv[1]):
        print(f"  {name:<12}{sec:8.2f} s")
    print(f"  {'(master)':<12}{prof['master']:8.2f} s")
    if args.compare:
        env = dict(os.environ, NEIGHBOR_COSIM_BATCHED_STEPS="0")
        proc = subprocess.run([sys.executable, __file__, "--orbit", args.orbit, "--scenario", args.scenario, "--json"],
                              env=env, capture_output=True, text=True, check=True)
        base = json.loads(proc.stdout.strip().splitlines()[-1])
        same = (base["steps"] == r.steps and base["total_propellant_kg"] == s["total_propellant_kg"]
                and base["reentry_years"] == s["simulated_years"])
        print(f"standard FMI calls only (same run, second process): {base['wall']:.1f} s wall, step loop "
              f"{base['loop']:.1f} s; batched step {base['loop'] / prof['loop']:.2f}x faster in the loop "
              f"({'the same results' if same else 'RESULTS DIFFER'})")


if __name__ == "__main__":
    main()
