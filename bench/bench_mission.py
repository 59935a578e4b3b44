"""Benchmark the full NEIGHBOR mission run.

    python bench/bench_mission.py [--orbit averaged|cowell] [--scenario 420km]

One run of the mission system from deployment to re-entry: 5 years idle, 30 days of grace, the
final contact, the de-orbit (10 min attitude determination, detumble, slew and the burn at
15 ms attitude steps), monitoring until the battery is empty, then decay to re-entry. Prints the
wall time, the steps and simulated time per schedule mode, and where the time goes: per
component (set inputs + doStep + get outputs) and the master itself. Target: under 120 s on a
2-core machine. The first run in a process includes numba compiling the orbit and atmosphere
kernels (about 5-10 s). Build first: python build_fmus.py
"""
import argparse
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
    args = ap.parse_args()
    t0 = time.perf_counter()
    s, r = mission.run_mission(args.scenario, args.orbit, profile=True)
    wall = time.perf_counter() - t0
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


if __name__ == "__main__":
    main()
