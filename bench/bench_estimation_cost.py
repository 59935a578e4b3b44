"""What attitude estimation costs against truth feedback, mission by mission (the 420 km
mission, closed-loop guidance and control, orbit-averaged system).

    python bench/bench_estimation_cost.py                 # 6 missions x 2 (about 10 min on 2 cores)
    python bench/bench_estimation_cost.py --cases 20 --workers 16

Case 0 is the nominal mission; case i > 0 takes the draws of run i - 1 of
examples/campaigns/mission_dispersion_420km.toml (tumble, mass, thruster misalignments, gyro
bias, sensor seeds). Each case flies twice from the same state:
1. with estimation (`--gnc closed-loop`): the controllers on the attitude estimator;
2. with truth feedback (`--gnc closed-loop-truth`), the rigid body starting the detumble in the
   state the first run had there (its q_BN and omega_BN_B: with estimation the host tumbles on
   through the attitude determination) and at the same time (attitude_determination_duration).
Prints per case and in distribution the RCS propellant per phase, the phase times, the largest
thrust-axis pointing error and the estimator's attitude error in the burn, and the difference
estimation - truth. The missions run on a Dask LocalCluster (one process per worker).
"""
import argparse
from pathlib import Path
import sys
import time

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from components.mission.modes import DeorbitPhase, MissionMode  # noqa: E402
from system_ssp.neighbor import mission  # noqa: E402
from system_ssp.tools.campaign import load_spec  # noqa: E402

SPEC = Path(__file__).resolve().parents[1] / "examples" / "campaigns" / "mission_dispersion_420km.toml"
PHASE_KEYS = ("detumble_propellant_g", "slew_propellant_g", "tracking_propellant_g", "detumble_time_s",
              "slew_time_s", "burn_pointing_error_deg")


def case_parameters(case):
    """The system parameters of a case: none for the nominal, else the campaign's draws."""
    if case == 0:
        return {}
    spec = load_spec(SPEC)
    _, values = spec.inputs(case - 1)
    return spec.overrides(values)


def fly_estimated(case):
    """(summary, rigid-body state and time at the detumble start) with estimation."""
    summary, r = mission.run_mission("420km", parameters=case_parameters(case), gnc="closed-loop")
    d = r.data
    i = int(np.flatnonzero((d["mission.mode"] == MissionMode.DEORBIT)
                           & (d["mission.phase"] == DeorbitPhase.DETUMBLE))[0])
    state = {**{f"dynamics.q0[{k}]": float(d[f"dynamics.q_BN[{k}]"][i]) for k in (1, 2, 3, 4)},
             **{f"dynamics.omega0[{k}]": float(d[f"dynamics.omega_BN_B[{k}]"][i]) for k in (1, 2, 3)},
             "mission.attitude_determination_duration": summary["attitude_determination_s"]}
    return _slim(summary), state


def fly_truth(case, state):
    summary, _ = mission.run_mission("420km", parameters={**case_parameters(case), **state},
                                     gnc="closed-loop-truth")
    return _slim(summary)


def _slim(s):
    keys = PHASE_KEYS + ("burn_knowledge_error_deg", "burn_knowledge_error_rms_deg", "attitude_determination_s",
                         "lifetime_with_burn_years", "wall_time_s", "error")
    return {k: s.get(k) for k in keys}


def main():
    from dask.distributed import Client, LocalCluster

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cases", type=int, default=6, help="missions (case 0 nominal, then the campaign's draws)")
    ap.add_argument("--workers", type=int, default=None, help="Dask workers (default: one per core)")
    args = ap.parse_args()
    t0 = time.perf_counter()
    with LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True) as cluster, \
            Client(cluster) as client:
        estimated = client.gather(client.map(fly_estimated, range(args.cases), pure=False))
        truth = client.gather(client.map(fly_truth, range(args.cases), [s for _, s in estimated], pure=False))
    wall = time.perf_counter() - t0
    rows = [(c, e, t) for c, ((e, _), t) in enumerate(zip(estimated, truth))]
    failed = [c for c, e, t in rows if e.get("error") or t.get("error")]
    print(f"{args.cases} cases x 2 missions in {wall:.0f} s; failed: {failed or 'none'}")
    print("per case: estimation / truth feedback")
    print(f"  {'case':>4} {'detumble g':>15} {'slew g':>15} {'tracking g':>15} {'detumble s':>15} "
          f"{'slew s':>15} {'pointing deg':>15} {'knowledge deg (rms/max)':>24}")
    for c, e, t in rows:
        if c in failed:
            print(f"  {c:>4} failed: {e.get('error') or t.get('error')}")
            continue
        cells = [f"{e[k]:7.2f}/{t[k]:<7.2f}" for k in PHASE_KEYS[:5]] + \
                [f"{e['burn_pointing_error_deg']:7.3f}/{t['burn_pointing_error_deg']:<7.3f}"]
        print(f"  {c:>4} " + " ".join(f"{x:>15}" for x in cells)
              + f" {e['burn_knowledge_error_rms_deg']:11.3f}/{e['burn_knowledge_error_deg']:<11.3f}")
    good = [(e, t) for c, e, t in rows if c not in failed]
    if not good:
        return
    print("estimation - truth over the cases: min, p50, max (mean)")
    for key in PHASE_KEYS:
        diff = np.array([e[key] - t[key] for e, t in good])
        print(f"  {key:<28}{diff.min():10.3f}{np.median(diff):10.3f}{diff.max():10.3f}   ({diff.mean():.3f})")
    rcs = np.array([sum(e[k] - t[k] for k in PHASE_KEYS[:3]) for e, t in good])
    print(f"  {'RCS propellant, all phases (g)':<28}{rcs.min():10.3f}{np.median(rcs):10.3f}{rcs.max():10.3f}"
          f"   ({rcs.mean():.3f})")
    knowledge = np.array([e["burn_knowledge_error_rms_deg"] for e, _ in good])
    worst = np.array([e["burn_knowledge_error_deg"] for e, _ in good])
    print(f"estimator attitude error in the burn (deg): RMS {knowledge.min():.3f}-{knowledge.max():.3f}, "
          f"largest after the first 10 s {worst.min():.3f}-{worst.max():.3f}")
    ratio = np.mean([e["wall_time_s"] for e, _ in good]) / np.mean([t["wall_time_s"] for _, t in good])
    print(f"wall time per mission: estimation / truth feedback = {ratio:.2f}")


if __name__ == "__main__":
    main()
