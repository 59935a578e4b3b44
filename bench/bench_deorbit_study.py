"""Benchmark the whole de-orbit lifetime study through the master.

    python bench/bench_deorbit_study.py [--model averaged|cowell] [--density jacchia_roberts]

Runs `system_ssp.deorbit_study.run_study` (3 thesis scenarios, with and without the burn) and
prints per run: simulated years, wall time, wall seconds per simulated year, steps; then the
total. Target (2-core machine): the full study with the averaged model under 60 s. For the
Cowell model, pass --scenarios 420km --max-years 1 to measure a year of the 420 km case.
Build first: python build_fmus.py
"""
import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from system_ssp.neighbor import deorbit_study  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--model", choices=list(deorbit_study.SYSTEMS), default="averaged")
    ap.add_argument("--density", default="jacchia_roberts")
    ap.add_argument("--scenarios", default=",".join(deorbit_study.THESIS))
    ap.add_argument("--max-years", type=float, default=150.0)
    args = ap.parse_args()
    t0 = time.perf_counter()
    summary = deorbit_study.run_study(args.model, args.density, args.scenarios.split(","),
                                      max_years=args.max_years)
    wall = time.perf_counter() - t0
    print(f"de-orbit study, model {args.model}, density {args.density}")
    print(f"{'run':<16}{'years':>9}{'wall s':>9}{'s/year':>9}{'steps':>9}  re-entered")
    for run, s in summary.items():
        years = s["lifetime_years"]
        print(f"{run:<16}{years:9.2f}{s['wall_time_s']:9.2f}{s['wall_time_s'] / years:9.3f}{s['steps']:9d}  "
              f"{s['reentered']}")
    sim_years = sum(s["lifetime_years"] for s in summary.values())
    print(f"total: {len(summary)} runs, {sim_years:.1f} simulated years, {wall:.1f} s wall "
          f"(including loading the system once), {wall / sim_years:.3f} s per simulated year")


if __name__ == "__main__":
    main()
