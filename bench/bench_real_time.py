"""Benchmark real-time pacing on the detumble system: how close to wall time the points are held.

    python bench/bench_real_time.py [--seconds 20] [--factors 1,10,100]

Runs build/ssp/detumble.ssp (15 ms steps, stop condition off) once unpaced, then paced at each
factor (`System.run(real_time=F)`), and prints per factor: the paced wall time against the ideal
(simulated time / F) as a ratio, the time slept, the overruns (points a whole step behind), the
late points and the worst lateness; and the unpaced run's wall time, the floor the pacing leaves
room above. Whether a point overruns depends on what else the machine runs: this is where the
overrun count is measured (tests/master/test_real_time.py checks that it is reported consistently,
not how many there are on the test machine). Build first: python build_fmus.py
"""
import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from system_ssp import System  # noqa: E402

SIGNALS = ["dynamics.omega_BN_B[1]", "dynamics.q_BN[4]", "detumble.torque_cmd_B[2]"]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=20.0, help="simulated seconds per run (default 20)")
    parser.add_argument("--factors", default="1,10,100", help="real-time factors, comma-separated (default 1,10,100)")
    args = parser.parse_args(argv)
    factors = [float(f) for f in args.factors.split(",")]
    path = ROOT / "build" / "ssp" / "detumble.ssp"
    if not path.is_file():
        print(f"{path} is missing: run python build_fmus.py first", file=sys.stderr)
        return 2
    with System(path) as system:
        def run(**pacing):
            return system.run(stop_time=args.seconds, stop_when=[], outputs=SIGNALS, **pacing)

        run()  # the first run loads the FMUs' code and numba's caches
        start = time.perf_counter()
        run()
        free = time.perf_counter() - start
        print(f"detumble, {args.seconds:g} s simulated: unpaced {free:.3f} s wall "
              f"({args.seconds / free:.0f}x real time)")
        print("| factor | wall / ideal | slept (s) | overruns | late points | worst lateness (ms) | points |")
        print("|---|---|---|---|---|---|---|")
        for factor in factors:
            p = run(real_time=factor).pacing
            ideal = args.seconds / factor
            print(f"| x{factor:g} | {p['wall_s'] / ideal:.4f} | {p['slept_s']:.3f} | {p['overruns']} | "
                  f"{p['late_points']} | {p['worst_lateness_s'] * 1e3:.3g} | {p['points']} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
