"""A campaign's throughput against the same runs one after another in one process.

    python bench/bench_campaign.py                 # 8 de-orbit lifetime runs (about 2 minutes here)
    python bench/bench_campaign.py --runs 32 --workers 16 --case detumble

Prints: the warm per-run time in one process (the baseline: a System loaded once, then the
runs); the campaign with 1 worker (per-run overhead of the machinery: scheduling, the worker's
own System, the Parquet rows, against the warm run); the campaign with N workers (parallel
efficiency = baseline / (N x campaign time)). The cluster's start-up is timed separately.
"""
import argparse
from pathlib import Path
import sys
import tempfile
import time

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from system_ssp.tools.campaign import load_spec  # noqa: E402
from system_ssp.tools.campaign import runner  # noqa: E402
from system_ssp.tools.campaign.worker import run_one  # noqa: E402

CASES = {
    "deorbit": """
[campaign]
system = "deorbit_lifetime"
parameter_sets = ["parameters/deorbit_lifetime_420km.ssv"]
runs = {runs}
seed = 1
[dispersions."orbit.Cd"]
distribution = "uniform"
low = 2.0
high = 2.4
[metrics]
lifetime_s = "stop_time"
""",
    "detumble": """
[campaign]
system = "detumble"
parameter_sets = ["parameters/detumble_case1.ssv"]
runs = {runs}
seed = 1
stop_time = 5.0
[parameters]
"dynamics.integrator" = "rk4"
[dispersions."dynamics.omega0[1]"]
distribution = "normal"
mean = 0.17
std = 0.02
[metrics]
end_s = "stop_time"
""",
}


def _warm(spec):
    run_one(spec, 0)


def in_worker_run_time(folder):
    """Sum of the runs' own wall times as the workers measured them (the rows' wall_s)."""
    return sum(r["wall_s"] for r in runner._read_rows(Path(folder)))


def campaign_time(spec, workers, folder, batch=1):
    """(cluster start-up s, each worker's first load and run s, campaign s with warm workers)."""
    t0 = time.perf_counter()
    client, cluster = runner._client(workers, None)
    client.wait_for_workers(workers)
    startup = time.perf_counter() - t0
    t0 = time.perf_counter()
    client.run(_warm, spec)  # every worker loads the system and compiles once, as in a long campaign
    warm = time.perf_counter() - t0
    from dask.distributed import as_completed

    t0 = time.perf_counter()
    try:
        out = runner._prepare_folder(spec, folder)
        runner._run(client, spec, out, list(range(spec.total_runs)), runner._columns(spec), False, as_completed,
                    batch)
    finally:
        client.close()
        cluster.close()
    return startup, warm, time.perf_counter() - t0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--case", choices=list(CASES), default="deorbit")
    ap.add_argument("--runs", type=int, default=8)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--batch", type=int, default=1, help="runs per task (as campaign --batch)")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        (tmp / "spec.toml").write_text(CASES[args.case].format(runs=args.runs))
        spec = load_spec(tmp / "spec.toml")
        run_one(spec, 0)  # warm this process: System loaded, kernels compiled
        t0 = time.perf_counter()
        for i in range(spec.total_runs):
            assert run_one(spec, i)["status"] in ("ok", "incomplete")
        seq = time.perf_counter() - t0
        per = seq / spec.total_runs
        print(f"{args.case}: {spec.total_runs} runs; one process, warm: {seq:.2f} s ({per:.3f} s per run)")
        start1, warm1, t1 = campaign_time(spec, 1, tmp / "one")
        overhead = (t1 - seq) / spec.total_runs
        print(f"campaign, 1 worker:  {t1:.2f} s: {overhead * 1e3:+.1f} ms per run, {100 * overhead / per:+.1f} % of a "
              f"warm run (once per campaign: {start1:.2f} s cluster start-up, {warm1:.2f} s the worker's first "
              "load and run)")
        runs1 = in_worker_run_time(tmp / "one")
        print(f"  of which the runs themselves, timed in the worker: {runs1:.2f} s ({100 * (runs1 / seq - 1):+.1f} % "
              f"against this process); the machinery (tasks, rows): {(t1 - runs1) / spec.total_runs * 1e3:.1f} ms "
              "per run")
        if args.batch > 1:
            _, _, tb = campaign_time(spec, 1, tmp / "batch", args.batch)
            runsb = in_worker_run_time(tmp / "batch")
            n = spec.total_runs
            print(f"campaign, 1 worker, {args.batch} runs per task: {tb:.2f} s: {(tb - seq) / n * 1e3:+.1f} ms per "
                  f"run; runs in the worker {runsb:.2f} s, machinery {(tb - runsb) / n * 1e3:.1f} ms per run")
        startn, warmn, tn = campaign_time(spec, args.workers, tmp / "n", args.batch)
        eff = seq / (args.workers * tn)
        print(f"campaign, {args.workers} workers: {tn:.2f} s: {seq / tn:.2f}x the one process, parallel efficiency "
              f"{100 * eff:.0f} % (once: {startn:.2f} s start-up, {warmn:.2f} s first load and run per worker)")


if __name__ == "__main__":
    main()
