"""The mission off the thesis' nominal point: examples/campaigns/mission_dispersion_<scenario>.toml
(closed-loop guidance and control on the attitude estimator; tumble up to 15 deg/s per axis in
either sense, mass 10-14 kg, inertia within 10 % of the box the flight software assumes, thrusters
misaligned and off in force, gyro bias and sensor noise; the 475 and 525 km campaigns extend the
420 km one) through the campaign runner on Dask.

    python bench/bench_dispersion.py                        # 100 runs at 420 km (about 80 min on 2 cores)
    python bench/bench_dispersion.py --scenario 525km --runs 20 --workers 16

Prints the success rate (with its 95 % Wilson interval), the share of runs that burned their
whole budget and re-entered within 5 years of the burn, and the distribution (min, 5th, 50th,
95th percentile, max) of each phase's duration, the RCS propellant and the lifetime after the
burn; per fault case (one fault in a fifth of the runs) how many de-orbited, ended in the
documented safe state or neither; and the wall time per run against the campaign's (parallel
efficiency). The results folder keeps runs.parquet and the figures; a rerun with the same --out
resumes.
"""
import argparse
import dataclasses
import os
from pathlib import Path
import sys
import time

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from components.core.constants import YEAR  # noqa: E402
from components.mission.neighbor import DATA_STORAGE_LIMIT_B  # noqa: E402
from system_ssp.neighbor import budgets  # noqa: E402
from system_ssp.neighbor.mission import DEFAULT_SCENARIO, SCENARIOS  # noqa: E402
from system_ssp.tools.campaign import load_spec, run_campaign  # noqa: E402
from system_ssp.tools.campaign.runner import _read_rows, wilson  # noqa: E402

CAMPAIGNS = Path(__file__).resolve().parents[1] / "examples" / "campaigns"
PHASES = {"detumble (s)": ("detumble_start_s", "slew_start_s", 1.0),
          "slew (s)": ("slew_start_s", "burn_start_s", 1.0),
          "burn (min)": ("burn_start_s", "monitoring_start_s", 60.0),
          "lifetime after the burn (years)": ("burn_start_s", "end_s", YEAR)}


def distribution(label, values):
    v = np.asarray(values, dtype=float)
    if not v.size:
        return f"  {label:<34} (no successful run)"
    p5, p50, p95 = np.percentile(v, [5, 50, 95])
    return f"  {label:<34}{v.min():10.3f}{p5:10.3f}{p50:10.3f}{p95:10.3f}{v.max():10.3f}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=100)
    ap.add_argument("--workers", type=int, default=None, help="Dask workers (default: one per core)")
    ap.add_argument("--scenario", choices=SCENARIOS, default=DEFAULT_SCENARIO)
    ap.add_argument("--out", default=None, help="results folder (default: results/dispersion_<scenario>)")
    args = ap.parse_args()
    args.out = args.out or f"results/dispersion_{args.scenario}"
    spec = dataclasses.replace(load_spec(CAMPAIGNS / f"mission_dispersion_{args.scenario}.toml"), runs=args.runs)
    t0 = time.perf_counter()
    summary = run_campaign(spec, args.out, workers=args.workers, progress=True)
    wall = time.perf_counter() - t0
    rows = sorted(_read_rows(Path(args.out)), key=lambda r: r["run"])
    ok = [r for r in rows if r["status"] in ("ok", "incomplete")]  # incomplete: never re-entered
    safe = [r for r in ok if r["safe_reason"]]  # the de-orbit abandoned for the safe state (no attitude)
    ok = [r for r in ok if not r["safe_reason"]]  # the runs that flew the de-orbit
    good = [r for r in ok if r["budget_spent"] and r["reentered"] and not r["detumble_timeouts"]
            and not r["slew_timeouts"] and r["end_s"] is not None and (r["end_s"] - r["burn_start_s"]) < 5 * YEAR]
    lo, hi = wilson(len(good), len(rows))
    print(f"{len(rows)} runs: {summary['ok']} ran, {summary['incomplete']} never re-entered, {summary['failed']} "
          f"failed, {summary['timeout']} timed out")
    print(f"de-orbit success (burned the budget, no phase timeout, re-entry < 5 years after the burn): "
          f"{len(good)}/{len(rows)} = {len(good) / len(rows):.1%} (95 % interval {lo:.1%} - {hi:.1%}); "
          f"{len(safe)} in the safe state (no attitude, no burn)")
    for case in sorted({r["fault"] for r in rows}):
        runs = [r for r in rows if r["fault"] == case]
        print(f"  fault {case}: {len(runs)} runs, {sum(r in good for r in runs)} de-orbited, "
              f"{sum(r in safe for r in runs)} in the safe state, {sum(r['bias_resets'] or 0 for r in runs)} bias "
              f"resets, {sum(r not in good and r not in safe for r in runs)} neither")
    for r in rows:
        if r not in good and r not in safe:
            print(f"  run {r['run']}: {r['status']} {r.get('error', '')[:160]}")
    print(f"  {'':<34}{'min':>10}{'p5':>10}{'p50':>10}{'p95':>10}{'max':>10}")
    for label, (start, end, unit) in PHASES.items():
        print(distribution(label, [(r[end] - r[start]) / unit for r in ok]))
    print(distribution("RCS propellant (g)", [1e3 * r["rcs_propellant_kg"] for r in ok]))
    print(distribution("burn propellant (kg)", [r["burn_propellant_kg"] for r in ok]))
    print(distribution("attitude determination (s)", [r["detumble_start_s"] - r["determination_start_s"] for r in ok]))
    print(distribution("largest knowledge error, whole run (deg)",
                       [np.degrees(r["knowledge_error_max_rad"]) for r in ok]))
    print(distribution("mean attitude NEES (3: consistent)", [r["nees_mean"] for r in ok]))
    print(distribution("steps above the NEES 95 % bound (%)", [100.0 * r["nees_over_fraction"] for r in ok]))
    # the budgets (system_ssp.neighbor.budgets): the 95th percentile against each allowance
    allowed = budgets.allowance(args.scenario)
    for label, values, limit in (
            ("RCS propellant (g)", [1e3 * r["rcs_propellant_kg"] for r in ok], allowed.rcs_g),
            ("total propellant (kg)", [r["burn_propellant_kg"] + r["rcs_propellant_kg"] for r in ok], allowed.tank_kg),
            ("largest data storage (MB)", [r["max_storage_B"] / 1e6 for r in ok], DATA_STORAGE_LIMIT_B / 1e6)):
        if values:
            p95, over = np.percentile(values, 95), sum(v > limit for v in values)
            print(f"  budget {label}: p95 {p95:.4g} against {limit:.4g}: {'within' if p95 <= limit else 'OVER'} "
                  f"({over} of {len(values)} runs over)")
    print(f"  ({allowed.describe()})")
    per_run = np.mean([r["wall_s"] for r in rows]) if rows else float("nan")
    workers = args.workers or len(os.sched_getaffinity(0))
    print(f"wall {wall:.0f} s for {len(rows) - summary['resumed_from']} new runs; {per_run:.1f} s per run in a worker; "
          f"parallel efficiency {per_run * (len(rows) - summary['resumed_from']) / (workers * wall):.0%} "
          f"on {workers} workers")
    print(f"results in {args.out}")


if __name__ == "__main__":
    main()
