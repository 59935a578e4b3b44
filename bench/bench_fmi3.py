"""The cost of running the product's systems with the FMI 3.0 FMUs against the FMI 2.0 ones,
in the same run.

    python bench/bench_fmi3.py [--repeat 3] [--systems detumble,slew,sunline]

For each system of build/ssp and build/ssp3 (built by `neighbor-cosim build`): the best wall
time of `--repeat` runs of the system's own experiment, alternating the two so machine load
hits both, and the ratio FMI 3.0 / FMI 2.0. The results themselves are compared, not timed,
by tests/master/test_fmi3_master.py.
"""
import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import system_ssp  # noqa: E402
from system_ssp.locations import BUILD  # noqa: E402


def wall_time(path):
    """The wall time of one run of the system's own experiment."""
    t0 = time.perf_counter()
    system_ssp.simulate(path)
    return time.perf_counter() - t0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--systems", default="detumble,slew,sunline")
    args = ap.parse_args(argv)
    print(f"{'system':<12} {'FMI 2.0 (s)':>12} {'FMI 3.0 (s)':>12} {'3.0 / 2.0':>10}")
    for name in args.systems.split(","):
        fmi2, fmi3 = BUILD / "ssp" / f"{name}.ssp", BUILD / "ssp3" / f"{name}.ssp"
        best2 = best3 = float("inf")
        for _ in range(args.repeat):  # alternate: load on the machine falls on both
            best2 = min(best2, wall_time(fmi2))
            best3 = min(best3, wall_time(fmi3))
        print(f"{name:<12} {best2:>12.3f} {best3:>12.3f} {best3 / best2:>10.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
